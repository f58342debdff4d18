# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Name maps that reorder, half-applied parameter requests, joint states beyond the URDF.

Issue 27, items 3, 6 and 9: a name map swapping two joints reordered the command
silently; a contact link could map to the root or a joint frame; a non-atomic
set_parameters request published commands computed with half of it; joint positions
beyond the URDF's limits were commanded; get_parameters of every parameter gave nothing.
"""

import time

from conftest import PLANAR
from cycle_inputs import joint_state, Slow
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.ros.node import COMMAND_QOS, GraspTorqueNode
import numpy as np
import pytest
from rcl_interfaces.srv import GetParameters, SetParameters
import rclpy
from rclpy.parameter import Parameter
from ros_harness import DOMAIN, Harness
from std_msgs.msg import Float64MultiArray

SWAP = ['joint1=joint3', 'joint3=joint1']  # two joints of the same torque limit


def start(**params):
    """Start a plain node in a context of its own; raise what its start raises."""
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=DOMAIN)
    overrides = [Parameter('scenario', value=str(PLANAR))]
    overrides += [Parameter(k, value=v) for k, v in params.items()]
    try:
        GraspTorqueNode(context=context, parameter_overrides=overrides).destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


def test_a_name_map_that_permutes_joints_needs_joints_given():
    with pytest.raises(InputError, match=r'^joints: must be given: the name map sends the '
                       r"scenario's joint 'joint1' to 'joint3'"):
        start(name_map=SWAP)
    # Given, the order is the user's: what stops this map now is the swapped fingers'
    # grasp itself (its normals point out of the object), no longer the order.
    with pytest.raises(InputError, match=r'^grasp.contacts\[0\].normal: '):
        start(name_map=SWAP, joints=['joint1', 'joint2', 'joint3', 'joint4'])


@pytest.mark.parametrize('target, why', [
    ('palm', "is the root 'palm'"), ('joint2', 'is a joint frame'),
    ('finger1_tip_joint', 'is a joint frame')])
def test_a_contact_link_may_not_map_to_the_root_or_a_joint_frame(target, why):
    with pytest.raises(InputError, match=rf"^grasp.contacts\[0\].link: '{target}' {why}"):
        start(name_map=[f'finger1_tip={target}'])


def test_the_command_order_is_in_diagnostics(planar):
    h = Harness(PLANAR)
    try:
        h.send_joint_state(*joint_state(planar))
        assert h.next_command() is not None
        assert h.spin_until(lambda: h.diagnostics, 2.0)
        assert h.diagnostics[-1]['command_joints'] == 'joint1,joint2,joint3,joint4'
    finally:
        h.close()


def test_a_request_is_applied_whole_before_a_command_uses_it(planar):
    h = Harness(PLANAR, joint_state_timeout=5.0)  # fresh inputs: the rule's cycle commands
    try:
        names, pos = joint_state(planar)
        h.send_joint_state(names, pos)
        assert h.next_command() is not None
        fmin = 1.5 * float(np.max(solve(planar).wrenches[:, 2]))
        client = h.tester.create_client(SetParameters, 'grasp_torque_node/set_parameters')
        # Not atomic: rclpy sets (and calls back) one parameter after the other; each
        # changes the command.
        request = SetParameters.Request(parameters=[
            Parameter('min_normal_force', value=fmin).to_parameter_msg(),
            Parameter('mu_tangential', value=0.8).to_parameter_msg()])
        counters = h.node.controller.counters
        before = counters.commands
        assert all(r.successful for r in h.call(client, request).results)
        h.spin_for(0.3)
        assert counters.commands == before + 1, 'one command per request, all of it applied'
        sent = h.commands[-1][1]
        h.send_joint_state(names, pos)
        np.testing.assert_allclose(h.next_command(), sent, atol=1e-9)
    finally:
        h.close()


def test_joint_positions_beyond_the_urdf_limits_are_rejected(planar):
    h = Harness(PLANAR, joint_limit_tolerance=0.1)
    try:
        names, pos = joint_state(planar)
        h.send_joint_state(names, pos)
        assert h.next_command() is not None
        n = len(h.commands)
        beyond = list(pos)
        beyond[0] = 2.0 + 0.15  # the planar hand's limits are +-2 rad
        h.send_joint_state(names, beyond)
        rejected = h.node.controller.counters.rejected
        assert h.spin_until(lambda: rejected['joint_states'] > 0, 2.0)
        k = rejected['joint_states']
        assert "position of 'joint1' is 2.15, beyond its URDF limits [-2, 2] by more than " \
               'joint_limit_tolerance (0.1)' in h.node.controller.last_rejection
        assert len(h.commands) == n
        within = list(pos)
        within[0] = 2.0 + 0.05  # within the tolerance: taken
        h.send_joint_state(names, within)
        assert h.spin_until(lambda: h.node.controller.inputs.q[0] == within[0], 2.0)
        assert rejected['joint_states'] == k
    finally:
        h.close()


def test_get_parameters_answers_for_every_parameter(planar):
    h = Harness(PLANAR)
    try:
        names = h.node._parameters.keys()
        client = h.tester.create_client(GetParameters, 'grasp_torque_node/get_parameters')
        values = h.call(client, GetParameters.Request(names=list(names))).values
        assert len(values) == len(names)
        assert list(h.node.get_parameter('name_map').value) == []
    finally:
        h.close()


def test_another_publisher_on_the_command_topic_is_an_error(planar):
    h = Harness(PLANAR)
    try:
        h.send_joint_state(*joint_state(planar))
        assert h.next_command() is not None
        assert h.spin_until(lambda: h.diagnostics, 2.0)
        assert h.diagnostics[-1]['command_topic.other_publishers'] == 'none'
        h.tester.create_publisher(Float64MultiArray, 'effort_commands', COMMAND_QOS)
        assert h.spin_until(
            lambda: h.diagnostics[-1]['command_topic.other_publishers'] == '/tester', 5.0)
        last = h.diagnostics[-1]  # its status named /grasp_torque_node (the harness's filter)
        assert last['_level'] == 2, last['_message']
        assert last['_message'].startswith('another publisher on /effort_commands (/tester); ')
        assert h.node.controller is not None  # the node goes on (docs/node.md, Faults)
    finally:
        h.close()


def test_the_solve_worker_keeps_to_its_share_and_sheds_load_early(planar):
    from grasp_torque_opt.ros.node import service
    from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
    from std_srvs.srv import Trigger

    h = Harness(PLANAR, joint_state_timeout=10.0)
    try:
        client = h.tester.create_client(Trigger, 'grasp_torque_node/solve', qos_profile=QoSProfile(
            history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE))
        assert h.spin_until(client.service_is_ready, 5.0)
        names, pos = joint_state(planar)
        h.send_joint_state(names, pos)
        assert h.next_command() is not None
        h.node.root.service.controller.solver = Slow(0.01)
        t0 = time.monotonic()
        futures = [client.call_async(Trigger.Request()) for _ in range(40)]
        n = len(h.commands)
        for _ in range(20):  # the loop answers joint states while the worker solves
            h.send_joint_state(names, pos)
            h.spin_for(0.01)
        assert h.spin_until(lambda: all(f.done() for f in futures), 30.0)
        elapsed = time.monotonic() - t0
        busy = [f for f in futures if f.result().message.startswith('busy: ')]
        # At most 10 queued (a few more solved meanwhile); 100 before: none was busy.
        assert len(busy) >= 25
        assert len(h.commands) - n >= 10
        # Each 10 ms solve is followed by a rest, so that the worker takes at most its
        # share of the time: the solved ones cannot have been answered sooner than this.
        solved = len(futures) - len(busy)
        assert elapsed >= 0.9 * (solved - 1) * 0.01 / service.WORKER_SHARE
    finally:
        h.close()
