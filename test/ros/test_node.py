# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""grasp_torque_node with real rclpy in-process: real topics, a real service call."""

import dataclasses
import json
import os
from pathlib import Path
import signal
import subprocess
import sys
import time

from conftest import ALLEGRO, ALLEGRO_URDF, PLANAR, ROOT
from cycle_inputs import base_poses, joint_state, Slow
from geometry_msgs.msg import PoseArray, WrenchStamped
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import resolve_urdf
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.ros.node import COMMAND_QOS, GraspTorqueNode, MAX_PENDING_SOLVES
import numpy as np
import pinocchio as pin
import pytest
import rclpy
from rclpy.duration import Duration
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from ros_harness import DOMAIN, Harness, NodeProcess
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray, String
from std_srvs.srv import Trigger
from visualization_msgs.msg import Marker

# Each run on its own domain, heard only on this machine.
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'


@pytest.fixture
def planar_node():
    h = Harness(PLANAR)
    yield h
    h.close()


def test_published_torques_are_the_cores_solution(planar_node, planar):
    q = planar.q.copy()
    q[planar.hand.idx_q[1]] += 0.01
    planar_node.send_joint_state(*joint_state(planar, q))
    cmd = planar_node.next_command()
    assert cmd is not None and cmd.shape == (4,)
    ref = solve(dataclasses.replace(planar, q=q))
    assert ref.optimal
    np.testing.assert_allclose(cmd, ref.tau, atol=1e-9)
    # The same state, joints shuffled and an extra joint with NaN: the same torques.
    names, pos = joint_state(planar, q)
    order = [2, 0, 3, 1]
    planar_node.send_joint_state([names[i] for i in order] + ['wrist'],
                                 [pos[i] for i in order] + [float('nan')])
    np.testing.assert_allclose(planar_node.next_command(), cmd, atol=1e-12)
    # Arrows for RViz: one per contact, from the contact point.
    assert planar_node.spin_until(lambda: any(len(m.markers) == 3
                                              for m in planar_node.markers), 2.0)
    arrows = [m for m in planar_node.markers[-1].markers if m.action == Marker.ADD]
    assert len(arrows) == 2 and arrows[0].header.frame_id == 'palm'
    # They vanish if the node dies: a finite lifetime of three marker periods (0.1 s).
    assert all(Duration.from_msg(m.lifetime).nanoseconds == 300_000_000 for m in arrows)
    # Diagnostics name the hand of the URDF.
    assert planar_node.spin_until(lambda: planar_node.diagnostics, 2.0)
    assert planar_node.diagnostics[-1]['_hardware_id'] == planar.hand.model.name
    maps = dataclasses.replace(planar, q=q).maps()
    start = arrows[0].points[0]
    np.testing.assert_allclose([start.x, start.y, start.z], maps.contacts[0].position,
                               atol=1e-9)


def test_service_returns_the_cli_json(planar_node, planar):
    planar_node.send_joint_state(*joint_state(planar))
    cmd = planar_node.next_command()
    future = planar_node.solve_client.call_async(Trigger.Request())
    assert planar_node.spin_until(future.done, 5.0)
    res = future.result()
    assert res.success, res.message
    d = json.loads(res.message)
    assert {'status', 'method', 'joints', 'tau', 'torque_norm', 'solve_time_s', 'certificate',
            'contacts'} <= set(d)
    assert d['status'] == 'optimal' and d['joints'] == planar.hand.joints
    np.testing.assert_allclose(d['command'], cmd, atol=1e-12)
    # Many calls while the loop runs: each answered, the loop keeps publishing.
    # (As many as the worker queues: beyond, the answer is "busy".)
    futures = [planar_node.solve_client.call_async(Trigger.Request())
               for _ in range(MAX_PENDING_SOLVES)]
    n = len(planar_node.commands)
    for _ in range(20):
        planar_node.send_joint_state(*joint_state(planar))
        planar_node.spin_for(0.01)
    assert planar_node.spin_until(lambda: all(f.done() for f in futures), 10.0)
    assert all(f.result().success for f in futures)
    assert len(planar_node.commands) - n >= 10


def test_service_says_why_without_inputs(planar_node):
    future = planar_node.solve_client.call_async(Trigger.Request())
    assert planar_node.spin_until(future.done, 5.0)
    assert not future.result().success
    assert future.result().message == 'cannot solve: no joint state yet'


@pytest.mark.parametrize('name,value,reason', [
    ('torque_limits', [1.0, 2.0], 'torque_limits: must have 4 entries, got 2'),
    ('torque_limits', [1.0, -2.0, 1.0, 1.0], 'torque_limits: every entry must be > 0'),
    ('polygon_sides', 2, 'polygon_sides'),
    ('fault_policy', 'explode', 'fault_policy: must be one of hold, zero'),
    ('mu_tangential', 0.0, 'mu_tangential'),
    ('joints', ['joint1'], 'read-only parameter: joints'),
    # The freeze: accepted as in range, they let one solve run for minutes.
    ('solver.max_iter', 100000, 'solver.max_iter'),
    ('solver.max_iter_in', 100000, 'solver.max_iter_in'),
    ('weights', [1e-12, 1e12, 1e-12, 1e12], 'weights: every entry must be in [1e-06, 1e+06]'),
    ('weights', [1e-4, 1e3, 1.0, 1.0], 'weights: the largest entry may be at most 1e+06 times '
     'the smallest, got 1e+07'),
    ('cycle_budget', 10.0, 'cycle_budget'),
    # Unbounded limits: 1e6 and 1e300 N m were accepted (URDF effort limits 10, 5, 10, 5).
    ('torque_limits', [1e6, 1.0, 1.0, 1.0], "torque_limits: 1e+06 N m for joint 'joint1' "
     'exceeds the URDF effort limit (10 N m); set torque_limits_above_urdf'),
    ('torque_limits', [1.0, 1.0, 1.0, 1e300], 'exceeds the URDF effort limit (5 N m)'),
    ('torque_limits', [10.0, 5.0, 10.0, 5.1], "joint 'joint4'"),
])
def test_bad_parameter_is_refused_with_its_reason(planar_node, name, value, reason):
    before = planar_node.node.get_parameter(name).value
    result = planar_node.node.set_parameters([Parameter(name, value=value)])[0]
    assert not result.successful
    assert reason in result.reason
    assert planar_node.node.get_parameter(name).value == before


def test_good_parameter_change_takes_effect(planar_node, planar):
    planar_node.send_joint_state(*joint_state(planar))
    free = planar_node.next_command()
    fmin = 1.5 * float(np.max(solve(planar).wrenches[:, 2]))
    assert planar_node.node.set_parameters(
        [Parameter('min_normal_force', value=fmin)])[0].successful
    planar_node.send_joint_state(*joint_state(planar))
    squeezed = planar_node.next_command()
    ref = solve(dataclasses.replace(planar, friction=dataclasses.replace(
        planar.friction, min_normal_force=fmin)))
    np.testing.assert_allclose(squeezed, ref.tau, atol=1e-9)
    assert np.linalg.norm(squeezed) > np.linalg.norm(free)


def malformed_joint_states(setup):
    names, pos = joint_state(setup)
    yield 'length', names, pos[:-1], '4 names but 3 positions'
    yield 'duplicate', names[:3] + names[:1], pos, "duplicate joint name 'joint1'"
    yield 'missing', names[:3] + ['other'], pos, 'missing commanded joint(s) joint4'
    yield 'nan', names, [pos[0], float('nan')] + pos[2:], "position of 'joint2' is not finite"


def test_malformed_inputs_give_no_command_and_a_diagnostic(planar_node, planar):
    for _, names, pos, reason in malformed_joint_states(planar):
        n = len(planar_node.commands)
        planar_node.send_joint_state(names, pos)
        assert planar_node.spin_until(
            lambda: planar_node.diagnostics and
            planar_node.diagnostics[-1]['last_rejection'] == f'joint_states: {reason}', 2.0), \
            reason
        assert len(planar_node.commands) == n
    assert planar_node.diagnostics[-1]['rejected.joint_states'] == '4'
    pos, quat = base_poses(planar)
    bad_contacts = [('palm', pos, quat * 1.1, 'contacts.poses[0].orientation: is not a unit '
                     'quaternion'),
                    ('finger9', pos, quat, 'contacts.header.frame_id: unknown frame '
                     "'finger9'"),
                    ('palm', pos[:1], quat[:1], 'contacts: 1 poses for 2 contacts')]
    for frame, p, q, reason in bad_contacts:
        planar_node.send_contacts(frame, p, q)
        assert planar_node.spin_until(
            lambda: planar_node.diagnostics and
            planar_node.diagnostics[-1]['last_rejection'].startswith(reason), 2.0), reason
    assert planar_node.commands == []  # rejected inputs never triggered a command
    # The bad contacts were not used: a good joint state gives the default grasp's torques.
    planar_node.send_joint_state(*joint_state(planar))
    np.testing.assert_allclose(planar_node.next_command(), solve(planar).tau, atol=1e-9)
    assert planar_node.diagnostics[-1]['rejected.contacts'] == '3'


def test_stale_contacts_stop_commands_within_timeout_plus_one_cycle(planar):
    timeout, period = 0.2, 0.02
    h = Harness(PLANAR, contacts_timeout=timeout, joint_state_timeout=1.0)
    try:
        pos, quat = base_poses(planar)
        h.send_contacts('palm', pos, quat)
        h.spin_for(0.05)
        t_contacts = time.monotonic()
        end = t_contacts + 0.6
        while time.monotonic() < end:
            h.send_joint_state(*joint_state(planar))
            h.spin_for(period)
        times = [t for t, _ in h.commands]
        assert len([t for t in times if t <= t_contacts + timeout]) >= 3
        # 30 ms for delivery and scheduling on a loaded 2-core machine.
        assert max(times) <= t_contacts + timeout + period + 0.03
        assert 'contacts stale' in h.diagnostics[-1]['fault']
    finally:
        h.close()


def test_stale_joint_states_apply_the_zero_policy(planar):
    h = Harness(PLANAR, joint_state_timeout=0.05, hold_time=0.05, fault_policy='zero')
    try:
        h.send_joint_state(*joint_state(planar))
        first = h.next_command()
        assert first is not None and np.linalg.norm(first) > 0
        zero = h.next_command(1.0)
        assert zero is not None and np.all(zero == 0.0)
        # 'in', not a prefix: a namesake left on the domain by an earlier test (discovery
        # forgets it late) puts its ERROR in front (seen twice in full runs).
        assert h.spin_until(lambda: h.diagnostics and
                            'zero torques published' in h.diagnostics[-1]['_message'], 2.0)
    finally:
        h.close()


def test_gravity_compensation_adds_g_of_q(allegro):
    gravity = [9.81, 0.0, 0.0]
    h = Harness(ALLEGRO, gravity_compensation=True, gravity=gravity)
    try:
        q = allegro.q.copy()
        q[allegro.hand.idx_q[5]] += 0.05
        h.send_joint_state(*joint_state(allegro, q))
        cmd = h.next_command()
        model = pin.buildModelFromUrdf(str(resolve_urdf(ALLEGRO_URDF, Path('.'))))
        model.gravity.linear = np.array(gravity)
        g = pin.computeGeneralizedGravity(model, model.createData(), q)[allegro.hand.idx_v]
        ref = solve(dataclasses.replace(GraspSetup.from_file(ALLEGRO), q=q, torque_offset=g))
        assert ref.optimal and np.linalg.norm(g) > 1e-3
        np.testing.assert_allclose(cmd, ref.tau + g, atol=1e-9)
        assert np.all(np.abs(cmd) <= allegro.hand.torque_limits)
    finally:
        h.close()


def test_qos_of_every_endpoint(planar_node):
    t = planar_node.tester

    def mine(infos):
        return [i for i in infos if i.node_name == 'grasp_torque_node']

    for topic in ('/joint_states', '/contacts', '/external_wrench'):
        (sub,) = mine(t.get_subscriptions_info_by_topic(topic))
        assert sub.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT, topic
        assert str(sub.topic_type).startswith(('sensor_msgs', 'geometry_msgs'))
    (cmd,) = mine(t.get_publishers_info_by_topic('/effort_commands'))
    assert cmd.qos_profile.reliability == ReliabilityPolicy.RELIABLE
    assert cmd.topic_type == 'std_msgs/msg/Float64MultiArray'
    (diag,) = mine(t.get_publishers_info_by_topic('/diagnostics'))
    assert diag.qos_profile.reliability == ReliabilityPolicy.RELIABLE
    (mk,) = mine(t.get_publishers_info_by_topic('/grasp_torque_node/contact_wrenches'))
    assert mk.topic_type == 'visualization_msgs/msg/MarkerArray'
    services = dict(t.get_service_names_and_types())
    assert services['/grasp_torque_node/solve'] == ['std_srvs/srv/Trigger']


def test_the_docs_document_every_parameter():
    from grasp_torque_opt.ros.node import PARAMETERS

    readme = ''.join(p.read_text() for p in [ROOT / 'README.md', *sorted(ROOT.glob('docs/*.md'))])
    for name in PARAMETERS:
        assert f'| `{name}` |' in readme, name


@pytest.mark.parametrize('as_path', [False, True])
def test_robot_description_gives_the_hand(planar, as_path):
    urdf = PLANAR.parent.parent / 'urdf' / 'planar_two_finger.urdf'
    h = Harness(PLANAR, robot_description=str(urdf) if as_path else urdf.read_text())
    try:
        h.send_joint_state(*joint_state(planar))
        np.testing.assert_allclose(h.next_command(), solve(planar).tau, atol=1e-9)
    finally:
        h.close()


def test_startup_errors_name_the_parameter():
    ctx = rclpy.Context()
    rclpy.init(context=ctx, domain_id=DOMAIN)
    try:
        with pytest.raises(InputError, match='^scenario: parameter not set'):
            GraspTorqueNode(context=ctx)
        with pytest.raises(InputError, match='^torque_limits: must have 4 entries, got 1'):
            GraspTorqueNode(context=ctx, parameter_overrides=[
                Parameter('scenario', value=str(PLANAR)),
                Parameter('torque_limits', value=[1.0])])
        # A node refused at start is gone from the graph at once (not at garbage collection).
        probe = rclpy.create_node('probe', context=ctx)
        assert ('grasp_torque_node', '/') not in probe.get_node_names_and_namespaces()
        probe.destroy_node()
    finally:
        rclpy.try_shutdown(context=ctx)


def test_stamped_command_carries_the_joint_states_stamp(planar):
    h = Harness(PLANAR, publish_stamped_command=True)
    try:
        stamped = []
        h.tester.create_subscription(JointState, 'grasp_torque_node/effort_commands_stamped',
                                     stamped.append, COMMAND_QOS)
        h.spin_until(lambda: h.node.count_subscribers(
            'grasp_torque_node/effort_commands_stamped') > 0, 5.0)
        msg = JointState(name=list(planar.hand.joints),
                         position=[float(planar.q[i]) for i in planar.hand.idx_q])
        msg.header.stamp.sec, msg.header.stamp.nanosec = 1234, 5678
        for sec in (1234, 1235):  # the second read by the first's layout
            h.js_pub.publish(msg)
            assert h.spin_until(lambda: len(stamped) == sec - 1233 and h.commands, 5.0)
            out = stamped[-1]
            assert (out.header.stamp.sec, out.header.stamp.nanosec) == (sec, 5678)
            assert list(out.name) == list(planar.hand.joints)
            assert out.header.frame_id == planar.hand.base_frame
            np.testing.assert_array_equal(out.effort, h.commands[-1][1])
            msg.header.stamp.sec += 1
        assert h.node.root.inputs.layout.read_here >= 1
    finally:
        h.close()


def test_joint_states_read_by_their_layout_command_as_rclpys_reading(planar_node, planar):
    """A driver's messages after its first are read from their bytes: the same commands."""
    h, layout = planar_node, planar_node.node.root.inputs.layout
    names, pos = joint_state(planar)
    read_before = layout.read_here
    for k in range(4):
        q = planar.q.copy()
        q[planar.hand.idx_q[1]] += 0.004 * k
        h.send_joint_state(*joint_state(planar, q))
        cmd = h.next_command()
        assert cmd is not None, k
        np.testing.assert_allclose(cmd, solve(dataclasses.replace(planar, q=q)).tau,
                                   atol=1e-9)
    assert layout.read_here - read_before >= 3  # all but the first, by the layout
    # A NaN read from the bytes is refused as rclpy's reading of it is.
    h.send_joint_state(names, [pos[0], float('nan')] + pos[2:])
    assert h.spin_until(lambda: h.diagnostics and h.diagnostics[-1]['last_rejection'] ==
                        "joint_states: position of 'joint2' is not finite", 2.0)
    assert layout.read_here - read_before >= 4


def test_stopping_applies_the_policy_in_process(planar):
    for policy, expect_zero in (('zero', True), ('hold', False)):
        # Long timeouts: the only zero command can come from the stop.
        h = Harness(PLANAR, fault_policy=policy, joint_state_timeout=5.0, hold_time=5.0)
        try:
            assert h.node.safe_stop() is False  # never commanded: nothing to undo
            h.send_joint_state(*joint_state(planar))
            assert h.next_command() is not None
            n = len(h.commands)
            assert h.node.safe_stop() is expect_zero
            h.spin_for(0.2)
            received = [c for _, c in h.commands[n:]]
            assert len(received) == (1 if expect_zero else 0)
            assert all(np.all(c == 0.0) for c in received)
        finally:
            h.close()


@pytest.mark.parametrize('sig,executor', [(signal.SIGINT, 'waitset'),
                                          (signal.SIGTERM, 'waitset'),
                                          (signal.SIGINT, 'single'), (signal.SIGTERM, 'single'),
                                          (signal.SIGINT, 'events')])
def test_the_process_publishes_zero_when_stopped_with_the_zero_policy(planar, sig, executor):
    """
    Stop the process with a signal: with fault_policy zero, zero torques are left.

    grasp_torque_node as users run it (any executor): it answers joint states, a signal
    stops it, and with fault_policy zero the effort controller is left with zero torques.
    """
    p = NodeProcess('grasp_torque_opt.ros.node',
                    ['--executor', executor, '--ros-args', '-p', f'scenario:={PLANAR}',
                     '-p', 'fault_policy:=zero', '-p', 'joint_state_timeout:=5.0',
                     '-p', 'hold_time:=5.0'], 'stop_tester')
    try:
        assert p.first_command(*joint_state(planar))
        assert np.linalg.norm(p.commands[-1]) > 0
        p.child.send_signal(sig)
        # Within 4 s: 5 s after the last joint state the stale policy would publish zeros
        # itself, and they would pass for the stop's (as they did while a SIGINT inherited
        # ignored, from a background job, left the node spinning).
        assert p.spin_until(lambda: np.all(p.commands[-1] == 0.0), 4.0), p.commands[-3:]
        # The zeros arrived (the safety promise); the process then ends cleanly.
        code, err = p.finish()
        assert code == 0, err
        assert 'Traceback' not in err, err
        assert 'stopped: zero torques published' in err, err
    finally:
        p.close()


def _command_at(h: Harness, state: tuple) -> np.ndarray:
    """Send a joint state (names, positions) and give the command it brings (asserted)."""
    h.send_joint_state(*state)
    command = h.next_command(5.0)
    assert command is not None
    return command


@pytest.mark.parametrize('backend', ['daqp', 'quadprog'])
def test_backend_parameter_switches_the_solver_and_keeps_the_optimum(allegro, backend):
    h = Harness(ALLEGRO)
    try:
        before = _command_at(h, joint_state(allegro))
        assert h.node.set_parameters([Parameter('solver.backend', value=backend)])[0].successful
        assert h.node.controller.solver.name == backend
        after = _command_at(h, joint_state(allegro))
        np.testing.assert_allclose(after, before, atol=1e-6)
        refused = h.node.set_parameters([Parameter('solver.backend', value='osqp')])[0]
        assert not refused.successful and 'solver.backend' in refused.reason
    finally:
        h.close()


def test_the_compiled_cycle_answers_over_ros_and_the_parameter_turns_it_off(allegro):
    # The Allegro node runs the compiled cycle (design.md section 2.6); solver.compiled
    # false, set over ROS, gives the Python cycle's command for the same state.
    h = Harness(ALLEGRO)
    try:
        compiled = _command_at(h, joint_state(allegro))
        assert h.node.controller.compiled_cycle is not None
        assert h.node.controller.compiled_cycle.solves >= 1
        assert h.spin_until(lambda: h.diagnostics and
                            h.diagnostics[-1].get('solver.compiled') == 'true', 3.0)
        assert h.node.set_parameters([Parameter('solver.compiled', value=False)])[0].successful
        python = _command_at(h, joint_state(allegro))
        np.testing.assert_allclose(python, compiled, atol=1e-6)
        assert h.spin_until(lambda: h.diagnostics and h.diagnostics[-1].get(
            'solver.compiled') == 'false: off (compiled: false)', 3.0)
    finally:
        h.close()


def test_lowering_the_limits_below_the_command_in_force_zeroes_it_at_once(allegro):
    """
    Lower the limits under the command in force: zeros are published at once.

    Hold policy, 0.63 N m in force, torque_limits lowered to 0.2 N m (unholdable): zeros
    reach the effort controller at once, without another joint state; before, nothing new
    was published and the controller kept 0.63 N m forever.
    """
    h = Harness(ALLEGRO, fault_policy='hold', hold_time=10.0, joint_state_timeout=10.0)
    try:
        w = WrenchStamped()
        w.wrench.force.x = float(allegro.external_wrench[0] * 6.2)
        h.wrench_pub.publish(w)
        h.spin_for(0.2)
        h.send_joint_state(*joint_state(allegro))
        cmd = h.next_command()
        assert cmd is not None and np.abs(cmd).max() > 0.6
        n = len(h.commands)
        assert h.node.set_parameters([Parameter('torque_limits', value=[0.2] * 16)])[0].successful
        assert h.spin_until(lambda: len(h.commands) > n, 2.0)
        assert np.all(h.commands[-1][1] == 0.0) and len(h.commands) == n + 1
    finally:
        h.close()


def test_limits_above_the_urdf_only_when_allowed_at_start(planar):
    h = Harness(PLANAR, torque_limits_above_urdf=True)
    try:
        node = h.node
        assert node.set_parameters([Parameter('torque_limits', value=[20.0] * 4)])[0].successful
        refused = node.set_parameters([Parameter('torque_limits', value=[2e4] * 4)])[0]
        assert not refused.successful and 'exceeds the largest limit accepted (10000 N m)' in \
            refused.reason
        h.send_joint_state(*joint_state(planar))
        assert h.next_command() is not None
    finally:
        h.close()


def test_a_joint_state_that_waited_in_the_queue_past_its_timeout_commands_nothing(planar):
    """
    Age inputs from the middleware's receipt: a message that waited is stale.

    Inputs are aged from the middleware's receipt, not from the callback: a joint state
    that waited 0.3 s for the executor (timeout 0.1 s) is stale when its callback runs. Before,
    a flood or a slow cycle let commands leave 165 ms after their joint state.
    """
    h = Harness(PLANAR, joint_state_timeout=0.1, hold_time=10.0)
    try:
        h.send_joint_state(*joint_state(planar))
        time.sleep(0.3)  # the executor is busy elsewhere: the message waits in the queue
        h.spin_for(0.3)
        assert h.commands == []
        assert h.node.controller.fault.startswith('joint_states stale')
        h.send_joint_state(*joint_state(planar))
        assert h.next_command() is not None  # taken at once: fresh
    finally:
        h.close()


def test_an_oversized_message_is_rejected_before_it_is_deserialized(planar):
    """
    Refuse an oversized message by its serialized length.

    20000 poses (1.1 MB) on contacts: refused by its serialized length. Deserializing
    10^5 poses took 0.8 s here, and a flood of them cut the command rate from 200 to 38 Hz.
    """
    from geometry_msgs.msg import Pose

    h = Harness(PLANAR)
    try:
        big = PoseArray(poses=[Pose() for _ in range(20000)])
        h.contacts_pub.publish(big)
        assert h.spin_until(lambda: h.node.controller.counters.rejected['contacts'] == 1, 5.0)
        assert h.node.controller.last_rejection == \
            'contacts: 1120028 bytes serialized, more than max_message_bytes (65536)'
        h.send_joint_state(*joint_state(planar))  # the loop goes on
        np.testing.assert_allclose(h.next_command(), solve(planar).tau, atol=1e-9)
    finally:
        h.close()


def test_a_flood_of_service_calls_is_answered_every_one(planar, monkeypatch):
    """
    Answer every one of a flood of ~/solve calls.

    300 concurrent ~/solve calls: each answered, solved or "busy" (before, beyond the 100
    queued requests the rest never were, silently: 872 to 900 of 1000). With solves slower
    than the calls come, at most MAX_PENDING_SOLVES are queued and the rest are "busy", and
    the control loop goes on meanwhile.
    """
    from grasp_torque_opt.ros.node import service as service_module
    from rclpy.qos import HistoryPolicy, QoSProfile

    h = Harness(PLANAR, joint_state_timeout=10.0)
    try:
        client = h.tester.create_client(Trigger, 'grasp_torque_node/solve', qos_profile=QoSProfile(
            history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE))
        assert h.spin_until(client.service_is_ready, 5.0)
        h.send_joint_state(*joint_state(planar))
        assert h.next_command() is not None

        def flood(n):
            futures = [client.call_async(Trigger.Request()) for _ in range(n)]
            assert h.spin_until(lambda: all(f.done() for f in futures), 30.0), \
                sum(f.done() for f in futures)
            answers = [f.result() for f in futures]
            busy = [a for a in answers if a.message.startswith('busy: ')]
            assert all(a.success for a in answers if not a.message.startswith('busy: '))
            assert all(not a.success for a in busy)
            return len(answers) - len(busy), len(busy)

        solved, _ = flood(300)
        assert solved >= service_module.MAX_PENDING_SOLVES
        monkeypatch.setattr(service_module, 'MAX_PENDING_SOLVES', 4)
        h.node.root.service.controller.solver = Slow(0.05)
        n = len(h.commands)
        futures = [client.call_async(Trigger.Request()) for _ in range(20)]
        for _ in range(10):  # the loop answers joint states while the service solves
            h.send_joint_state(*joint_state(planar))
            h.spin_for(0.02)
        assert len(h.commands) - n >= 5
        assert h.spin_until(lambda: all(f.done() for f in futures), 30.0)
        answers = [f.result() for f in futures]
        busy = [a for a in answers if a.message.startswith('busy: 4 solves queued')]
        assert busy and all(a.success for a in answers if a not in busy)
    finally:
        h.close()


def test_a_second_node_of_the_same_name_refuses_to_run(planar):
    """
    Refuse to run beside a running node of the same name.

    Two grasp_torque_nodes on one domain both drove effort_commands, and parameter reads
    and writes went to either. One already running: a second one started exits with code 2
    and one line naming the other, before it takes any input; the first reports it.
    """
    first = Harness(PLANAR)
    env = dict(os.environ, ROS_DOMAIN_ID=str(DOMAIN), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    second = subprocess.Popen([sys.executable, '-m', 'grasp_torque_opt.ros.node', '--ros-args',
                               '-p', f'scenario:={PLANAR}', '-p', 'startup_check_time:=10.0'],
                              env=env, stderr=subprocess.PIPE, text=True)
    try:
        first.send_joint_state(*joint_state(planar))
        assert first.next_command() is not None
        end = time.monotonic() + 15.0
        while second.poll() is None and time.monotonic() < end:
            first.spin_for(0.1)
        assert second.returncode == 2
        err = second.stderr.read()
        lines = [line for line in err.splitlines() if 'error' in line]
        assert lines == ['grasp_torque_node: error: another node named /grasp_torque_node is on '
                         f'this domain (ROS_DOMAIN_ID {DOMAIN}): refusing to run, as both would '
                         'drive effort_commands (stop it, or give this one another name with '
                         '--ros-args -r __node:=NAME)'], err
        first.send_joint_state(*joint_state(planar))  # the first goes on
        assert first.next_command() is not None
    finally:
        if second.poll() is None:
            second.kill()
        first.close()


def test_a_running_node_reports_another_of_its_name(planar):
    h = Harness(PLANAR)
    other = GraspTorqueNode(context=h.context,
                            parameter_overrides=[Parameter('scenario', value=str(PLANAR))])
    try:
        assert h.spin_until(lambda: h.diagnostics and
                            h.diagnostics[-1].get('duplicate_nodes') == '1', 5.0)
        d = h.diagnostics[-1]
        assert d['_level'] == 2 and d['_message'].startswith(
            'another node named /grasp_torque_node is on this domain; ')
    finally:
        other.destroy_node()
        h.close()


def test_incompatible_peers_are_found_from_the_graph_and_told_once(planar_node):
    h = planar_node
    # No QoS event handlers of the node's own topics wait in its executor.
    root = h.node.root
    ours = [root.outputs.command_pub, root.outputs.marker_pub, root.status.pub,
            *h.node.subscriptions]
    assert all(e.event_handlers == [] for e in ours)
    assert h.spin_until(lambda: h.diagnostics and
                        h.diagnostics[-1].get('incompatible_peers') == 'none', 5.0)
    # Another process's peers, as a user's would be (one participant refuses two types
    # on one topic): a latched effort controller, and a publisher of another type.
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=DOMAIN)
    other = rclpy.create_node('other_peer', context=context)
    latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
    try:
        bad_sub = other.create_subscription(Float64MultiArray, 'effort_commands',
                                            lambda _: None, latched)
        bad_pub = other.create_publisher(String, 'contacts', 1)

        def both():
            d = h.diagnostics[-1] if h.diagnostics else {}
            text = d.get('incompatible_peers', '')
            return ('/effort_commands: subscription of /other_peer' in text
                    and '/contacts: publisher of /other_peer' in text)

        assert h.spin_until(both, 10.0), h.diagnostics[-1]
        d = h.diagnostics[-1]
        assert 'Volatile publisher and transient local subscription' in d['incompatible_peers']
        assert ('type std_msgs/msg/String, not geometry_msgs/msg/PoseArray'
                in d['incompatible_peers'])
        assert d['_level'] >= 1 and '2 incompatible peer(s)' in d['_message']
        h.spin_for(0.5)  # several diagnostics periods: each peer is told once
        told = [m.msg for m in h.logs if 'no messages will pass' in m.msg]
        assert len(told) == 2 and told[0] != told[1], told
        other.destroy_subscription(bad_sub)
        other.destroy_publisher(bad_pub)
        assert h.spin_until(lambda: h.diagnostics[-1].get('incompatible_peers') == 'none',
                            10.0), h.diagnostics[-1]
    finally:
        other.destroy_node()
        rclpy.shutdown(context=context)


def test_the_graph_is_asked_a_step_a_tick_never_all_in_one_callback(planar_node):
    # The graph's endpoint queries went from /diagnostics' callback (some thirty of them,
    # about half a millisecond) to the graph timer, one topic a tick: the same findings.
    h = planar_node
    node, status = h.node, h.node.root.status
    asked = []
    for name in ('get_publishers_info_by_topic', 'get_subscriptions_info_by_topic'):
        query = getattr(node, name)
        setattr(node, name, lambda topic, query=query: asked.append(topic) or query(topic))
    try:
        watched = len(node.root.peers)
        assert watched >= 5  # the planar node's topics: inputs, outputs, /diagnostics
        for _ in range(2 * (watched + 1)):
            asked.clear()
            status.on_graph()
            assert 1 <= len(asked) <= 2, asked  # one topic: its publishers, subscriptions
        asked.clear()
        status.on_diagnostics()
        assert asked == []
        assert node.root.peers.checked_all()
        d_before = len(h.diagnostics)
        assert h.spin_until(lambda: len(h.diagnostics) > d_before, 2.0)
        assert h.diagnostics[-1]['incompatible_peers'] == 'none'
        assert h.diagnostics[-1]['command_topic.other_publishers'] == 'none'
    finally:
        for name in ('get_publishers_info_by_topic', 'get_subscriptions_info_by_topic'):
            vars(node).pop(name, None)


def _fifo_threads(pid: int) -> dict[int, int]:
    """Give {thread id: SCHED_FIFO priority} of a process's SCHED_FIFO threads, from /proc."""
    out = {}
    for task in Path(f'/proc/{pid}/task').iterdir():
        fields = (task / 'stat').read_text().rsplit(')', 1)[1].split()
        priority, policy = int(fields[37]), int(fields[38])  # rt_priority, policy (41st)
        if policy == os.SCHED_FIFO:
            out[int(task.name)] = priority
    return out


def _fifo_allowed() -> bool:
    """Whether this process may ask SCHED_FIFO (asked from a thread that then goes back)."""
    from grasp_torque_opt.ros import realtime
    import threading

    answer = []

    def probe():
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(1))
            answer.append(True)
        except OSError:
            answer.append(False)
        realtime.normal_scheduling()

    t = threading.Thread(target=probe)
    t.start()
    t.join()
    return answer[0]


@pytest.mark.parametrize('priority', [50, 0])
def test_the_executor_thread_alone_asks_sched_fifo(planar, priority):
    """
    The executable's spinning thread asks SCHED_FIFO at thread_priority, as controller_manager.

    Only that thread: the solve worker it starts and the middleware's threads stay normal.
    Where the system refuses, the node says so and runs on.
    """
    from diagnostic_msgs.msg import DiagnosticArray

    p = NodeProcess('grasp_torque_opt.ros.node',
                    ['--ros-args', '-p', f'scenario:={PLANAR}', '-p', 'diagnostics_period:=0.1',
                     '-p', 'joint_state_timeout:=5.0', '-p', f'thread_priority:={priority}'],
                    'fifo_tester')
    seen = []
    p.tester.create_subscription(
        DiagnosticArray, '/diagnostics',
        lambda m: seen.extend(kv.value for s in m.status for kv in s.values
                              if kv.key == 'executor_thread'), 10)
    try:
        assert p.first_command(*joint_state(planar))
        client = p.tester.create_client(Trigger, 'grasp_torque_node/solve')
        assert p.call(client, Trigger.Request()).success  # the worker thread exists now
        assert p.spin_until(lambda: bool(seen), 5.0)
        fifo = _fifo_threads(p.child.pid)
        granted = bool(priority) and _fifo_allowed()
        if granted:
            assert fifo == {p.child.pid: priority}, fifo  # the main thread, and it alone
            assert seen[-1] == f'SCHED_FIFO {priority}'
        else:
            assert fifo == {}, fifo
            assert seen[-1] == 'SCHED_OTHER'
        p.child.send_signal(signal.SIGINT)
        code, err = p.finish()
        assert code == 0 and 'Traceback' not in err, err
        said = ('executor thread: SCHED_FIFO 50, switch interval 0.5 ms' if granted
                else 'refused' if priority else 'executor thread: left as it is')
        assert said in err, err
    finally:
        p.close()
