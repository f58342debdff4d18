# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Contact and gravity lies are rejected, and flapping inputs do not chatter the motors.

Issue 27, items 2 and 4: flipped normals were certified (commands that pull), contacts
of another finger were accepted, zero gravity was accepted, and inputs alternating
between two values made every command a full step.
"""

from conftest import PLANAR
from cycle_inputs import base_poses, flipped, fresh, joint_state, tilted
from grasp_torque_opt.control.inputs.contacts import ContactsReading
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
import numpy as np
from rclpy.parameter import Parameter
from ros_harness import Harness


def test_flipped_normals_are_rejected_and_never_commanded(planar):
    h = Harness(PLANAR)
    try:
        names, pos = joint_state(planar)
        h.send_joint_state(names, pos)
        first = h.next_command()
        assert first is not None
        points, quat = base_poses(planar)
        h.send_contacts('', points, flipped(quat))
        h.assert_contacts_refused('points away from grasp.object_origin', names, pos, first,
                                  atol=1e-9, timeout=2.0)
    finally:
        h.close()


def test_contacts_of_another_finger_are_rejected(planar):
    h = Harness(PLANAR)
    try:
        h.send_joint_state(*joint_state(planar))
        assert h.next_command() is not None
        points, quat = base_poses(planar)
        h.send_contacts('', points[::-1], quat[::-1])  # the two fingertips swapped
        assert h.spin_until(lambda: h.node.controller.counters.rejected['contacts'] == 1, 2.0)
        assert "from its link 'finger1_tip', beyond max_contact_link_distance (0.05 m)" in \
            h.node.controller.last_rejection
    finally:
        h.close()


def steps(commands) -> np.ndarray:
    """Give the largest change of any joint's torque between consecutive commands [N m]."""
    cmds = np.array([c for _, c in commands])
    return np.abs(np.diff(cmds, axis=0)).max(axis=1)


def flapping(h: Harness, names, pos, send) -> list:
    """Alternate an input between two values, one per joint state; the commands that came."""
    n = len(h.commands)
    for k in range(100):
        send(k % 2 == 0)
        h.spin_for(0.002)
        h.send_joint_state(names, pos)
        h.next_command(0.5)
    return h.commands[n:]


def test_flapping_contacts_do_not_chatter(planar):
    points, quat = base_poses(planar)
    other = tilted(quat, 0.05)
    # The full step between the two grasps, from a controller of its own.
    ends = []
    for q in (quat, other):
        ctrl = fresh(planar)
        ctrl.take('joint_states', JointStateReading(*joint_state(planar)), 0.0)
        ctrl.take('contacts', ContactsReading('', points, q), 0.0)
        ends.append(ctrl.cycle(0.0).command)
    full = float(np.abs(ends[0] - ends[1]).max())
    assert full > 0.05  # a 0.05 rad turn of the normals: 0.09 N m
    rate = 1.0  # N m/s
    h = Harness(PLANAR, max_torque_rate=rate)
    try:
        names, pos = joint_state(planar)
        h.send_contacts('', points, quat)
        h.send_joint_state(names, pos)
        assert h.next_command() is not None
        commands = flapping(h, names, pos,
                            lambda odd: h.send_contacts('', points, other if odd else quat))
        assert len(commands) > 50 and h.node.controller.counters.rejected['contacts'] == 0
        # Each step at most the rate times the time between the commands' joint states
        # (the arrival times here, with 20 ms for the delivery's jitter).
        times = np.array([t for t, _ in commands])
        assert (steps(commands) <= rate * (np.diff(times) + 0.02)).all()
        assert steps(commands).max() < 0.5 * full
        assert h.node.controller.counters.slew_limited > 0
    finally:
        h.close()


def test_gravity_outside_its_bounds_is_rejected(planar):
    h = Harness(PLANAR, gravity_compensation=True)
    try:
        h.send_joint_state(*joint_state(planar))
        assert h.next_command() is not None
        for vector in ([0.0, 0.0, 0.0], [0.0, 0.0, 1e-9], [0.0, 0.0, -30.0]):
            h.send_gravity('', vector)
        assert h.spin_until(lambda: h.node.controller.counters.rejected.get('gravity') == 3,
                            2.0)
        assert 'outside gravity_norm_bounds [5, 15]' in h.node.controller.last_rejection
        assert h.node.controller.inputs.gravity is None
        (result,) = h.node.set_parameters([Parameter('gravity', value=[0.0, 0.0, 0.0])])
        assert not result.successful and 'outside gravity_norm_bounds' in result.reason
    finally:
        h.close()


def test_zero_gravity_is_allowed_by_its_bounds(planar):
    h = Harness(PLANAR, gravity_compensation=True, gravity_norm_bounds=[0.0, 15.0],
                gravity=[0.0, 0.0, 0.0])
    try:
        h.send_joint_state(*joint_state(planar))
        assert h.next_command() is not None
        h.send_gravity('', [0.0, 0.0, 0.0])
        assert h.spin_until(lambda: h.node.controller.inputs.gravity is not None, 2.0)
    finally:
        h.close()


def test_flapping_gravity_does_not_chatter(planar):
    h = Harness(PLANAR, gravity_compensation=True, gravity=[9.81, 0.0, 0.0])
    try:
        names, pos = joint_state(planar)
        h.send_gravity('', [9.81, 0.0, 0.0])
        h.send_joint_state(names, pos)
        assert h.next_command() is not None
        full = 2.0 * float(np.abs(h.node.controller.last.gravity_torque).max())  # +x to -x
        assert full > 0.05
        commands = flapping(h, names, pos, lambda odd: h.send_gravity(
            '', [-9.81 if odd else 9.81, 0.0, 0.0]))
        assert len(commands) > 50
        # The gravity in use turns (never cuts through zero): its norm stays within the
        # bounds both ends meet. How far it turned depends on the time between the
        # messages (max_gravity_rate times it), which a loaded machine stretches.
        g = h.node.controller.inputs.gravity
        assert abs(np.linalg.norm(g) - 9.81) < 1e-9
        assert steps(commands).max() < 0.25 * full
    finally:
        h.close()
