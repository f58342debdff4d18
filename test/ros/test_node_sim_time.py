# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The fault path and the stop do not depend on /clock (use_sim_time with a clock that stops).

With use_sim_time and no /clock, the ROS clock reads 0 and never moves: timers on it
never fire, and a spin loop that waits for them never wakes.
"""

import signal
import time

from conftest import PLANAR
from cycle_inputs import joint_state
import numpy as np
from rclpy.parameter import Parameter
from ros_harness import Harness, NodeProcess


def test_a_dead_driver_is_zeroed_with_sim_time_and_no_clock(planar):
    h = Harness(PLANAR, use_sim_time=True, fault_policy='zero', joint_state_timeout=0.05,
                hold_time=0.05)
    try:
        assert h.node.get_clock().now().nanoseconds == 0  # no /clock: time stands still
        h.send_joint_state(*joint_state(planar))
        first = h.next_command()
        assert first is not None and np.any(first != 0.0)
        t0 = time.monotonic()  # the driver dies: no more joint states
        assert h.spin_until(lambda: np.all(h.commands[-1][1] == 0.0), 2.0), \
            'no zero command after the joint states stopped'
        assert time.monotonic() - t0 < 0.05 + 0.05 + 0.5
    finally:
        h.close()


def test_use_sim_time_is_fixed_after_start(planar):
    h = Harness(PLANAR)
    try:
        (result,) = h.node.set_parameters([Parameter('use_sim_time', value=True)])
        assert not result.successful and result.reason.startswith('use_sim_time: fixed')
        assert not h.node.get_parameter('use_sim_time').value
    finally:
        h.close()


def _stops_on(module, args, name, sig):
    p = NodeProcess(module, ['--ros-args', *args, '-p', 'startup_check_time:=0.0'], name)
    try:
        # Started (its signal handlers are in before its node exists) and, for the managed
        # node, waiting unconfigured: seen in the graph, however loaded the machine.
        assert p.spin_until(lambda: ('grasp_torque_node', '/') in
                            p.tester.get_node_names_and_namespaces()
                            or p.child.poll() is not None, 60.0)
        time.sleep(0.5)
        assert p.child.poll() is None, p.finish()[1]
        p.child.send_signal(sig)
        code, err = p.finish(timeout=5.0)
        assert code == 0 and 'Traceback' not in err, err
    finally:
        p.close()


def test_sigterm_ends_the_plain_node_with_sim_time_and_no_clock():
    args = ['-p', f'scenario:={PLANAR}', '-p', 'use_sim_time:=true']
    _stops_on('grasp_torque_opt.ros.node', args, 'sim_time_tester', signal.SIGTERM)


def test_sigint_ends_the_unconfigured_managed_node():
    _stops_on('grasp_torque_opt.ros.lifecycle_node', ['-p', f'scenario:={PLANAR}'],
              'unconfigured_tester', signal.SIGINT)
