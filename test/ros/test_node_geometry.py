# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
Contacts from geometry in the node, the object_pose input and ~/contact_wrench.

On the Allegro ball grasp, with contact_geometry.enabled.

Each command is checked against an independent solve: the contacts found by coal's
distance (GeometryContacts with analytic=False, not the node's closed form), the grasp
solved by the core.
"""

import dataclasses
import time

from conftest import ALLEGRO
from cycle_inputs import joint_state
from geometry_msgs.msg import PoseStamped, WrenchStamped
from grasp_torque_opt.core.geometry_contacts import GeometryContacts
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import resolve_urdf
from grasp_torque_opt.core.object_geometry import object_pose
from grasp_torque_opt.core.scenario import load_scenario, weight_wrench
from grasp_torque_opt.methods.dispatch import solve
import numpy as np
import pinocchio as pin
import pytest
from rclpy.qos import qos_profile_sensor_data
from ros_harness import Harness

SCENARIO = load_scenario(ALLEGRO)
SETUP = GraspSetup.from_file(ALLEGRO)
LINKS = [c.link for c in SCENARIO.contacts]
TOL = 1e-3
POSE = object_pose(SCENARIO.object.position, SCENARIO.object.rpy)
MODEL = SETUP.hand.model
COAL = GeometryContacts.bind(SETUP.hand, resolve_urdf(SCENARIO.urdf, SCENARIO.base_dir),
                             SCENARIO.object, TOL, LINKS, analytic=False)


def idx(joint):
    return MODEL.joints[MODEL.getJointId(joint)].idx_q


def reference(q, pose=POSE, links=None):
    """Solve the grasp at q with coal's contacts (all candidates within 2 tol, or ``links``)."""
    found = COAL.contacts(q, pose, tolerance=2 * TOL)
    specs = [s for s in found.specs() if links is None or s.link in links]
    moved = pose.act(POSE.actInv(SCENARIO.object_origin))
    obj = dataclasses.replace(SCENARIO.object, position=pose.translation.copy())
    load = SCENARIO.extra_wrench + weight_wrench(obj, SCENARIO.gravity, moved)
    setup = dataclasses.replace(SETUP, q=q, contacts=specs, object_origin=moved,
                                external_wrench=load)
    return solve(setup), specs


def opened(distance, joint='joint_1.0', link='link_3.0_tip'):
    """Give q with ``joint`` opened until ``link`` is ``distance`` from the ball (bisection)."""
    lo, hi = -0.2, 0.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        q = SETUP.q.copy()
        q[idx(joint)] += mid
        if COAL.distances(q, POSE)[link] > distance:
            lo = mid
        else:
            hi = mid
    q = SETUP.q.copy()
    q[idx(joint)] += 0.5 * (lo + hi)
    return q


class GeometryHarness(Harness):

    def __init__(self, **params):
        super().__init__(ALLEGRO, contact_geometry__enabled=True, **params)
        self.pose_pub = self.tester.create_publisher(PoseStamped, 'object_pose',
                                                     qos_profile_sensor_data)
        self.wrenches = []
        self.tester.create_subscription(WrenchStamped, 'grasp_torque_node/contact_wrench',
                                        self.wrenches.append, 100)
        assert self.spin_until(lambda: self.pose_pub.get_subscription_count() > 0, 10.0)

    def command_at(self, q):
        self.send_joint_state(*joint_state(SETUP, q))
        return self.next_command(timeout=1.0)

    def send_pose(self, position, quat=(0.0, 0.0, 0.0, 1.0), frame=''):
        msg = PoseStamped()
        msg.header.frame_id = frame
        p, o = msg.pose.position, msg.pose.orientation
        p.x, p.y, p.z = (float(v) for v in position)
        o.x, o.y, o.z, o.w = (float(v) for v in quat)
        self.pose_pub.publish(msg)
        self.spin_for(0.02)

    def diag(self, key, since=None):
        since = time.monotonic() if since is None else since
        n = len(self.diagnostics)
        self.spin_until(lambda: len(self.diagnostics) > n + 1, 2.0)
        return self.diagnostics[-1]


def test_contacts_from_geometry_are_the_scenarios_and_the_command_the_cores():
    ref, specs = reference(SETUP.q)
    assert ref.optimal and [s.link for s in specs] == LINKS
    for s, hand_made in zip(specs, SCENARIO.contacts):  # the 0.1 mm and 0.01 rad
        assert np.linalg.norm(s.position - hand_made.position) < 1e-4
        oMl = pin.SE3(SETUP.hand.data.oMf[MODEL.getFrameId(s.link)])
        towards = SCENARIO.object_origin - oMl.act(hand_made.position)  # the scenario's rule
        cos = s.normal @ towards / np.linalg.norm(towards)
        assert np.arccos(min(cos, 1.0)) < 0.01
    h = GeometryHarness()
    try:
        cmd = h.command_at(SETUP.q)
        np.testing.assert_allclose(cmd, ref.tau, atol=1e-6)
        d = h.diag('contacts.links')
        assert d['contacts.source'] == 'geometry' and d['contacts.links'] == ','.join(LINKS)
        assert d['contacts.changes'] == '0'
        # ~/contact_wrench: one message per contact, in its link's frame; moved to the
        # object origin in the base frame, the four balance the ball's weight.
        h.spin_until(lambda: len(h.wrenches) >= 8, 2.0)
        last = {m.header.frame_id: m for m in h.wrenches[-4:]}
        assert sorted(last) == sorted(LINKS)
        pin.framesForwardKinematics(MODEL, SETUP.hand.data, SETUP.q)
        total = np.zeros(6)
        for link, m in last.items():
            oMl = SETUP.hand.data.oMf[MODEL.getFrameId(link)]
            f = oMl.rotation @ [m.wrench.force.x, m.wrench.force.y, m.wrench.force.z]
            t = oMl.rotation @ [m.wrench.torque.x, m.wrench.torque.y, m.wrench.torque.z]
            arm = oMl.translation - SCENARIO.object_origin
            total += np.concatenate((f, t + np.cross(arm, f)))
            assert f @ (SCENARIO.object_origin - oMl.translation) > 0  # pushes, inward
        np.testing.assert_allclose(total, -SETUP.external_wrench, atol=1e-5)
    finally:
        h.close()


def test_rolling_fingers_move_the_contacts_and_the_command_stays_certified():
    h = GeometryHarness()
    try:
        first = reference(SETUP.q)[1][0].position
        for s in (0.25, 0.5, 0.75, 1.0):
            # Index finger: the proximal joint opens, the distal closes so that the tip
            # stays on the ball (rolls over it).
            q = SETUP.q.copy()
            q[idx('joint_1.0')] -= 0.01 * s
            lo, hi = 0.0, 0.1
            for _ in range(50):
                q[idx('joint_3.0')] = SETUP.q[idx('joint_3.0')] + 0.5 * (lo + hi)
                if COAL.distances(q, POSE)['link_3.0_tip'] > 0.0:
                    lo = 0.5 * (lo + hi)
                else:
                    hi = 0.5 * (lo + hi)
            ref, specs = reference(q)
            assert ref.optimal and [c.link for c in specs] == LINKS
            np.testing.assert_allclose(h.command_at(q), ref.tau, atol=1e-6)
        # The tip rolled: its contact point moved over the tip sphere (in its own frame).
        assert np.linalg.norm(specs[0].position - first) > 3e-4
        # Without the geometry (the scenario's point fixed in the tip), another command.
        fixed = solve(dataclasses.replace(SETUP, q=q))
        assert np.abs(fixed.tau - ref.tau).max() > 1e-4  # 100 times the tolerance
        assert h.diag('contacts.changes')['contacts.changes'] == '0'
    finally:
        h.close()


@pytest.mark.parametrize('rate', [1e6, 1.0])
def test_a_lifted_finger_drops_its_contact_and_is_never_in_a_command(rate):
    h = GeometryHarness(max_torque_rate=rate)
    try:
        h.command_at(SETUP.q)
        before = h.command_at(SETUP.q)
        q = opened(3 * TOL)  # the index tip 3 mm off the ball: beyond the release
        ref, specs = reference(q)
        assert 'link_3.0_tip' not in [c.link for c in specs]
        cmd = h.command_at(q)
        d = h.diag('contacts.changes')
        assert d['contacts.links'] == ','.join(LINKS[1:]) and d['contacts.changes'] == '1'
        if not ref.optimal:  # the grasp cannot be held without it: a fault, nothing published
            assert cmd is None and d['fault'] != 'none'
        elif rate > 1e3:  # recomputed with the three left, reached in one step
            np.testing.assert_allclose(cmd, ref.tau, atol=1e-6)
        else:  # a step of the rate rule across the change: the lifted contact fades out
            assert np.abs(cmd - before).max() <= rate * 0.005 + 1e-9
            assert int(d['slew_limited']) >= 1 and int(d['slew_refused']) == 0
            return
        # It comes back: four again, a second change.
        np.testing.assert_allclose(h.command_at(SETUP.q), reference(SETUP.q)[0].tau, atol=1e-6)
        assert h.diag('contacts.changes')['contacts.changes'] == '2'
    finally:
        h.close()


@pytest.mark.parametrize('release', [2.0, 1.0])
def test_a_tip_dithering_at_the_tolerance_does_not_flip_the_set(release):
    h = GeometryHarness(contact_geometry__release=release)
    try:
        h.command_at(SETUP.q)
        near, far = opened(0.9 * TOL), opened(1.1 * TOL)
        for _ in range(10):
            h.command_at(far)
            h.command_at(near)
        changes = int(h.diag('contacts.changes')['contacts.changes'])
        if release == 1.0:  # without hysteresis it flips every cycle
            assert changes >= 15
        else:
            assert changes == 0
            h.command_at(opened(2.5 * TOL))  # beyond the release: it leaves, once
            between = opened(1.5 * TOL)
            for _ in range(5):
                h.command_at(between)  # and does not come back until within the tolerance
            d = h.diag('contacts.changes')
            assert d['contacts.changes'] == '1' and 'link_3.0_tip' not in d['contacts.links']
    finally:
        h.close()


def test_the_object_pose_moves_the_contacts_and_the_load():
    h = GeometryHarness()
    try:
        h.command_at(SETUP.q)
        shift = np.array([0.0, -5e-4, 3e-4])
        moved = pin.SE3(np.eye(3), SCENARIO.object.position + shift)
        ref, _ = reference(SETUP.q, moved)
        assert ref.optimal
        h.send_pose(moved.translation)
        np.testing.assert_allclose(h.command_at(SETUP.q), ref.tau, atol=1e-6)
        assert np.abs(ref.tau - reference(SETUP.q)[0].tau).max() > 1e-3
        # The same pose in a model frame (a moving finger link's), placed at the joint state.
        pin.framesForwardKinematics(MODEL, SETUP.hand.data, SETUP.q)
        oMf = SETUP.hand.data.oMf[MODEL.getFrameId('link_9.0')]
        local = oMf.actInv(moved)
        quat = pin.Quaternion(local.rotation).coeffs()  # x, y, z, w
        h.send_pose(local.translation, quat, 'link_9.0')
        np.testing.assert_allclose(h.command_at(SETUP.q), ref.tau, atol=1e-6)
        d = h.diag('object_pose')
        assert d['object_pose'] == 'in use'
    finally:
        h.close()


def test_a_bad_object_pose_is_rejected_and_never_used():
    h = GeometryHarness()
    try:
        nominal = reference(SETUP.q)[0].tau
        centre = SCENARIO.object.position
        bad = [((np.nan, 0.0, 0.0), (0, 0, 0, 1), 'object_pose.pose.position'),
               (centre, (0, 0, 0, 2.0), 'not a unit quaternion'),
               (centre + [0.1, 0.0, 0.0], (0, 0, 0, 1), 'object_pose.max_offset'),
               (centre, (0, 0, 0, 1), 'neither a frame of the hand')]
        for n, (p, quat, why) in enumerate(bad, 1):
            h.send_pose(p, quat, 'nowhere' if n == 4 else '')
            np.testing.assert_allclose(h.command_at(SETUP.q), nominal, atol=1e-6)
            h.spin_until(lambda: bool(h.diagnostics) and int(
                h.diagnostics[-1].get('rejected.object_pose', 0)) >= n, 2.0)
            d = h.diagnostics[-1]
            assert int(d['rejected.object_pose']) == n and why in d['last_rejection'], d
            assert d['object_pose'].startswith('none received')
    finally:
        h.close()
