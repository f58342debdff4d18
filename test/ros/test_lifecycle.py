# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The managed node over its real lifecycle services, from a separate client node.

Transitions go through ``/grasp_torque_node/change_state`` and states are read
from ``/grasp_torque_node/get_state``; parameters are set through the node's
``set_parameters`` service; commands are what a subscriber on the domain receives.
"""

import json
import signal

from conftest import PLANAR, scenario_doc, setup_from_doc
from cycle_inputs import joint_state
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.ros.node import SERVICE_QOS
from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState, GetState
import numpy as np
import pytest
from rcl_interfaces.msg import Log
from rcl_interfaces.srv import GetParameters, SetParameters
from rclpy.parameter import Parameter
from ros_harness import LifecycleHarness, NodeProcess
from std_srvs.srv import Trigger

CONFIGURE = Transition.TRANSITION_CONFIGURE
ACTIVATE = Transition.TRANSITION_ACTIVATE
DEACTIVATE = Transition.TRANSITION_DEACTIVATE
CLEANUP = Transition.TRANSITION_CLEANUP
SHUTDOWN_ACTIVE = Transition.TRANSITION_ACTIVE_SHUTDOWN


def errors(h: LifecycleHarness) -> list[str]:
    """Give the node's ERROR log lines, as /rosout carried them."""
    return [m.msg for m in h.logs if m.level == Log.ERROR]


@pytest.mark.parametrize('params,reason', [
    # The node's own check (a value rclpy accepts).
    ({'fault_policy': 'explode'}, 'configure failed: fault_policy: must be one of hold, zero'),
    # Out of rclpy's range: it refused the value at declaration, and the node went on.
    ({'polygon_sides': 2}, 'configure failed: polygon_sides: the value given at start was '
     'refused (Parameter polygon_sides out of range. Min: 3, Max: 64, value: 2); set it, '
     'then configure again'),
    # A count only the hand can check.
    ({'torque_limits': [1.0, 2.0]}, 'configure failed: torque_limits: must have 4 entries, '
     'got 2'),
    ({'name_map': ['joint1']}, 'configure failed: name_map[0]: must be '
     "SCENARIO_NAME=URDF_NAME, got 'joint1'"),
])
def test_configure_with_a_bad_parameter_fails_naming_it_then_configures_once_set(
        planar, params, reason):
    good = {'fault_policy': 'hold', 'polygon_sides': 8, 'torque_limits': [10.0, 5.0, 10.0, 5.0],
            'name_map': ['joint1=joint1']}
    h = LifecycleHarness(PLANAR, **params)
    try:
        assert h.state() == 'unconfigured'
        assert not h.transition(CONFIGURE)
        assert h.state() == 'unconfigured'
        assert h.spin_until(lambda: reason in errors(h), 5.0), errors(h)
        assert not any('Traceback' in line for line in errors(h))
        assert h.node.controller is None  # nothing kept from the failed configure
        name = next(iter(params))
        assert [r.successful for r in h.set_parameters(**{name: good[name]})] == [True]
        assert h.transition(CONFIGURE), errors(h)
        assert h.state() == 'inactive'
    finally:
        h.close()


def test_a_missing_scenario_fails_configure_not_the_process():
    h = LifecycleHarness(None)
    try:
        assert not h.transition(CONFIGURE)
        assert h.spin_until(lambda: 'configure failed: scenario: parameter not set (a scenario '
                            'file gives the default contacts and load)' in errors(h), 5.0)
        answer = h.call(h.solve_client, Trigger.Request())
        assert not answer.success
        assert answer.message == 'cannot solve: not configured (lifecycle state unconfigured)'
    finally:
        h.close()


def test_commands_only_while_active_and_deactivate_takes_the_zero_policy(planar):
    # Long timeouts: no zero command can come from a stale input.
    h = LifecycleHarness(PLANAR, fault_policy='zero', joint_state_timeout=5.0, hold_time=5.0)
    names, pos = joint_state(planar)
    ref = solve(planar)
    assert ref.optimal
    try:
        assert h.transition(CONFIGURE)
        assert h.state() == 'inactive'
        assert h.spin_until(h.subscribed, 10.0)
        # Inactive: inputs are taken, nothing is commanded, the service solves.
        for _ in range(5):
            h.send_joint_state(names, pos)
            h.spin_for(0.02)
        h.spin_for(0.2)
        assert h.commands == []
        answer = h.call(h.solve_client, Trigger.Request())
        assert answer.success, answer.message
        np.testing.assert_allclose(json.loads(answer.message)['command'], ref.tau, atol=1e-9)
        assert h.spin_until(lambda: h.diagnostics and 'inactive (lifecycle): no commands'
                            in h.diagnostics[-1]['_message'], 5.0)
        # Active: each joint state commands the certified torques.
        assert h.transition(ACTIVATE)
        assert h.state() == 'active'
        received = len(h.commands)  # the fresh joint state may already have commanded
        h.send_joint_state(names, pos)
        cmd = h.next_command()
        assert cmd is not None and len(h.commands) > received
        np.testing.assert_allclose(cmd, ref.tau, atol=1e-9)
        # Deactivate: exactly one zero command (the safe action), then nothing more.
        n = len(h.commands)
        assert h.transition(DEACTIVATE)
        assert h.state() == 'inactive'
        h.spin_for(0.2)
        assert len(h.commands) == n + 1 and np.all(h.commands[-1][1] == 0.0)
        for _ in range(10):
            h.send_joint_state(names, pos)
            h.spin_for(0.02)
        h.spin_for(0.2)
        assert len(h.commands) == n + 1
        # Activate again: the fresh joint state commands at once, and the next ones too.
        assert h.transition(ACTIVATE)
        assert h.spin_until(lambda: len(h.commands) > n + 1, 2.0)
        np.testing.assert_allclose(h.commands[-1][1], ref.tau, atol=1e-9)
        h.send_joint_state(names, pos)
        np.testing.assert_allclose(h.next_command(), ref.tau, atol=1e-9)
        # Shut down from active: the safe action again, then finalized.
        n = len(h.commands)
        assert h.transition(SHUTDOWN_ACTIVE)
        assert h.state() == 'finalized'
        h.spin_for(0.2)
        assert len(h.commands) == n + 1 and np.all(h.commands[-1][1] == 0.0)
        h.send_joint_state(names, pos)
        h.spin_for(0.3)
        assert len(h.commands) == n + 1
    finally:
        h.close()


def test_deactivate_with_the_hold_policy_publishes_nothing(planar):
    h = LifecycleHarness(PLANAR, fault_policy='hold', joint_state_timeout=5.0, hold_time=5.0)
    names, pos = joint_state(planar)
    try:
        assert h.transition(CONFIGURE) and h.transition(ACTIVATE)
        assert h.spin_until(h.subscribed, 10.0)
        h.send_joint_state(names, pos)
        assert h.next_command() is not None
        n = len(h.commands)
        assert h.transition(DEACTIVATE)
        h.send_joint_state(names, pos)
        h.spin_for(0.3)
        assert len(h.commands) == n  # the last certified command stays in force
    finally:
        h.close()


def test_a_read_only_parameter_is_fixed_while_configured_and_cleanup_forgets_the_scenarios(
        planar):
    h = LifecycleHarness(PLANAR)
    try:
        # Unconfigured: the scenario's parameters have no value yet (rclpy's service then
        # answers no value at all).
        get = h.tester.create_client(GetParameters, 'grasp_torque_node/get_parameters')
        request = GetParameters.Request(names=['torque_limits', 'joints'])
        assert list(h.call(get, request).values) == []
        assert h.transition(CONFIGURE)
        values = h.call(get, request).values
        assert list(values[0].double_array_value) == [10.0, 5.0, 10.0, 5.0]
        assert list(values[1].string_array_value) == list(planar.hand.joints)
        refused = h.set_parameters(joints=['joint2', 'joint1', 'joint3', 'joint4'])[0]
        assert not refused.successful
        assert refused.reason == ('joints: fixed while configured: set it while unconfigured, '
                                  'then configure')
        fmin = 1.5 * float(np.max(solve(planar).wrenches[:, 2]))
        # A run-time parameter changes while configured.
        assert h.set_parameters(min_normal_force=fmin)[0].successful
        assert h.transition(CLEANUP)
        assert h.state() == 'unconfigured' and h.node.controller is None
        assert list(h.call(get, request).values) == []  # the scenario's are emptied again
        # Unconfigured, the joints can be set: the next configure commands in that order
        # (the scenario's per-joint limits, 10 5 10 5 N m, follow the order given).
        order = ['joint3', 'joint4', 'joint1', 'joint2']
        assert h.set_parameters(joints=order)[0].successful
        assert h.transition(CONFIGURE), errors(h)
        assert h.transition(ACTIVATE)
        assert h.node.get_parameter('min_normal_force').value == fmin  # the user's, kept
        assert h.spin_until(h.subscribed, 10.0)
        h.send_joint_state(*joint_state(planar))
        cmd = h.next_command()
        # The reference: the same grasp with the joints in that order and that f_min.
        doc = scenario_doc(PLANAR)
        doc['hand']['joints'] = order
        doc['friction']['min_normal_force'] = fmin
        ref = solve(setup_from_doc(doc))
        assert ref.optimal
        np.testing.assert_allclose(cmd, ref.tau, atol=1e-9)
        assert not np.allclose(cmd[[2, 3, 0, 1]], solve(planar).tau, atol=1e-3)  # it mattered
    finally:
        h.close()


def test_the_executable_is_driven_over_the_domain_and_stops_with_the_safe_action(planar):
    """
    Run grasp_torque_lifecycle_node as users do, and drive it from another process.

    A bad parameter fails configure with one logged line and no traceback; set over the
    parameter service, configure and activate succeed; commands flow; SIGINT takes the
    zero policy's safe action and the process ends cleanly.
    """
    p = NodeProcess('grasp_torque_opt.ros.lifecycle_node',
                    ['--ros-args', '-p', f'scenario:={PLANAR}',
                     '-p', 'fault_policy:=explode', '-p', 'polygon_sides:=2',
                     '-p', 'joint_state_timeout:=5.0', '-p', 'hold_time:=5.0',
                     '-p', 'startup_check_time:=0.0'], 'lifecycle_tester')
    change = p.tester.create_client(ChangeState, 'grasp_torque_node/change_state')
    state = p.tester.create_client(GetState, 'grasp_torque_node/get_state')
    params = p.tester.create_client(SetParameters, 'grasp_torque_node/set_parameters')
    solve_client = p.tester.create_client(Trigger, 'grasp_torque_node/solve',
                                          qos_profile=SERVICE_QOS)

    def transition(tid):
        return p.call(change, ChangeState.Request(transition=Transition(id=tid))).success

    try:
        assert p.call(state, GetState.Request()).current_state.label == 'unconfigured'
        assert not transition(CONFIGURE)
        assert p.call(state, GetState.Request()).current_state.label == 'unconfigured'
        results = p.call(params, SetParameters.Request(parameters=[
            Parameter('fault_policy', value='zero').to_parameter_msg(),
            Parameter('polygon_sides', value=3).to_parameter_msg()])).results
        assert [r.successful for r in results] == [True, True]
        assert transition(CONFIGURE) and transition(ACTIVATE)
        assert p.first_command(*joint_state(planar))
        np.testing.assert_allclose(p.commands[-1], solve(planar).tau, atol=1e-9)
        assert p.call(solve_client, Trigger.Request()).success
        p.child.send_signal(signal.SIGINT)
        assert p.spin_until(lambda: np.all(p.commands[-1] == 0.0), 4.0), p.commands[-3:]
        code, err = p.finish()
        assert code == 0, err
        assert 'Traceback' not in err, err
        failed = [line for line in err.splitlines() if 'configure failed' in line]
        assert len(failed) == 1 and 'polygon_sides: the value given at start was refused' in \
            failed[0], err
        assert 'stopped: zero torques published' in err, err
    finally:
        p.close()
