# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The object's state from the fingertips (issue 32, item 1), on the Allegro ball grasp.

Checked against independent formulations: the rigid motion of the contact points made
by hand (a known object motion, the fingers placed by it with an IK of their own), the
linearized least squares G^T dx = J dq built from Pinocchio's frame Jacobians here, and
the twist against a finite difference of the displacement.
"""

from conftest import ALLEGRO, CONFIG, setup_from_doc
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.object_from_hand import kabsch, ObjectFromHand
from grasp_torque_opt.core.object_geometry import object_pose
from grasp_torque_opt.native import loader
import numpy as np
import pinocchio as pin
import pytest

SETUP = GraspSetup.from_file(ALLEGRO)
MODEL = SETUP.hand.model
POSE = object_pose(SETUP.object_origin, np.zeros(3))


@pytest.fixture(params=['compiled', 'numpy'])
def est(request):
    module = loader.fast_cycle if request.param == 'compiled' else None
    if request.param == 'compiled' and module is None:
        pytest.skip(loader.IMPORT_ERROR)
    return ObjectFromHand(SETUP.hand, SETUP.contacts, SETUP.q, POSE, module=module)


def linearized(dq):
    """Solve G^T dx = J dq in least squares, G and J written here from the frame Jacobians."""
    data = MODEL.createData()
    pin.computeJointJacobians(MODEL, data, SETUP.q)
    pin.updateFramePlacements(MODEL, data)
    rows, rhs = [], []
    for c in SETUP.contacts:
        f = MODEL.getFrameId(c.link)
        p = data.oMf[f].act(c.position)
        # The Jacobian of the point itself: a frame at the point, axes of the world.
        J = pin.getFrameJacobian(MODEL, data, f, pin.LOCAL)
        R = data.oMf[f].rotation
        Jp = R @ (J[:3] - pin.skew(c.position) @ J[3:])
        rhs.append(Jp @ dq)
        rows.append(np.hstack((np.eye(3), -pin.skew(p - POSE.translation))))
    return np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]


def test_at_the_reference_the_object_has_not_moved(est):
    e = est.estimate(SETUP.q, np.zeros(MODEL.nv))
    assert np.abs(e.translation).max() < 1e-15 and np.abs(e.rotation).max() < 1e-12
    assert np.abs(e.twist).max() == 0.0 and e.residual < 1e-15


def test_a_small_motion_is_the_linearized_least_squares(est):
    rng = np.random.default_rng(3)
    for _ in range(5):
        dq = 1e-5 * rng.standard_normal(MODEL.nv)
        e = est.estimate(SETUP.q + dq)
        dx = linearized(dq)
        np.testing.assert_allclose(e.translation, dx[:3], atol=1e-3 * np.abs(dx).max())
        np.testing.assert_allclose(e.rotation, dx[3:], atol=1e-3 * np.abs(dx).max())


def test_the_twist_is_the_displacements_rate(est):
    rng = np.random.default_rng(4)
    v = rng.standard_normal(MODEL.nv)
    dt = 1e-6
    e = est.estimate(SETUP.q, v)
    moved = est.estimate(pin.integrate(MODEL, SETUP.q, v * dt))
    np.testing.assert_allclose(e.twist[:3], moved.translation / dt, rtol=1e-3, atol=1e-6)
    np.testing.assert_allclose(e.twist[3:], moved.rotation / dt, rtol=1e-3, atol=1e-5)


def test_a_rigid_motion_of_the_points_is_found_whole(est):
    """Reference points carried by a known motion: the object's pose is that motion."""
    motion = pin.SE3(pin.exp3(np.array([0.05, -0.1, 0.2])), np.array([0.004, -0.002, 0.003]))
    est.points0 = est.points0.copy()
    moved = est.points0 @ motion.rotation.T + motion.translation
    est.points = lambda q: moved  # the fingers exactly where the motion puts the points
    est.compiled = None  # (the compiled estimate computes its own points)
    e = est.estimate(SETUP.q)
    np.testing.assert_allclose(e.pose.homogeneous, (motion * POSE).homogeneous, atol=1e-12)
    assert e.residual < 1e-12


def test_one_finger_off_the_rigid_motion_shows_in_the_residual(est):
    q = SETUP.q.copy()
    q[MODEL.joints[MODEL.getJointId('joint_1.0')].idx_q] -= 0.05  # the index lifts
    assert est.estimate(q).residual > 1e-3


def test_kabsch_is_scipys_align_vectors_rotation():
    """The closed form against scipy's Rotation.align_vectors, reflections included."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(5)
    for n, noise in ((3, 0.0), (4, 1e-3), (4, 0.5), (8, 2.0)):
        for _ in range(20):
            b = rng.standard_normal((n, 3))
            R = Rotation.random(random_state=rng).as_matrix()
            a = b @ R.T + noise * rng.standard_normal((n, 3))
            a, b = a - a.mean(axis=0), b - b.mean(axis=0)
            got = kabsch(a, b)
            np.testing.assert_allclose(got, Rotation.align_vectors(a, b)[0].as_matrix(),
                                       atol=1e-9)
            assert abs(np.linalg.det(got) - 1.0) < 1e-12  # a rotation, never a reflection


def test_the_residuals_are_each_points_distance_from_the_rigid_motion(est):
    """Each contact's residual: its point at q against the reference point carried."""
    q = SETUP.q.copy()
    q[MODEL.joints[MODEL.getJointId('joint_1.0')].idx_q] -= 0.05  # the index lifts
    e = est.estimate(q)
    moved = e.pose * POSE.inverse()
    carried = np.array([moved.act(p) for p in est.points0])
    np.testing.assert_allclose(e.residuals, np.linalg.norm(est.points(q) - carried, axis=1),
                               atol=1e-15)
    assert e.residual == e.residuals.max() > 1e-3


def test_the_compiled_fit_is_scipys_align_vectors():
    """The compiled Kabsch fit against scipy's Rotation.align_vectors, and t, residuals."""
    from scipy.spatial.transform import Rotation

    if loader.fast_cycle is None:
        pytest.skip(loader.IMPORT_ERROR)
    rng = np.random.default_rng(6)
    for n, noise in ((3, 0.0), (4, 1e-3), (4, 0.5), (8, 2.0)):
        for _ in range(20):
            p0 = rng.standard_normal((n, 3))
            R = Rotation.random(random_state=rng).as_matrix()
            p = p0 @ R.T + rng.standard_normal(3) + noise * rng.standard_normal((n, 3))
            got_R, got_t, got_res = loader.fast_cycle.rigid_fit(p0, p)
            a, b = p - p.mean(axis=0), p0 - p0.mean(axis=0)
            ref = Rotation.align_vectors(a, b)[0].as_matrix()
            np.testing.assert_allclose(got_R, ref, atol=1e-9)
            t = p.mean(axis=0) - ref @ p0.mean(axis=0)
            np.testing.assert_allclose(got_t, t, atol=1e-9)
            np.testing.assert_allclose(got_res, np.linalg.norm(p - (p0 @ ref.T + t), axis=1),
                                       atol=1e-9)
            assert abs(np.linalg.det(got_R) - 1.0) < 1e-12


@pytest.mark.parametrize('hand', ['allegro', 'g1'])
def test_the_compiled_estimate_is_the_numpy_one(hand):
    """The same estimates with the points and the fit compiled and in numpy."""
    from g1_grasp import ARM_Q, g1_doc

    # The G1's in its palm's frame (base_link), the arm posed: points moved into it.
    setup = SETUP if hand == 'allegro' else setup_from_doc(g1_doc(posture=ARM_Q), CONFIG)
    pose = object_pose(setup.object_origin, np.zeros(3))
    if loader.fast_cycle is None:
        pytest.skip(loader.IMPORT_ERROR)
    fast = ObjectFromHand(setup.hand, setup.contacts, setup.q, pose, module=loader.fast_cycle)
    slow = ObjectFromHand(setup.hand, setup.contacts, setup.q, pose)
    assert fast.compiled is not None and slow.compiled is None
    rng = np.random.default_rng(9)
    model = setup.hand.model
    for _ in range(10):
        q = setup.q + rng.uniform(-0.1, 0.1, model.nq)
        a, b = fast.estimate(q), slow.estimate(q)
        np.testing.assert_allclose(a.pose.homogeneous, b.pose.homogeneous, atol=1e-12)
        np.testing.assert_allclose(a.residuals, b.residuals, atol=1e-12)
        np.testing.assert_allclose(a.rotation, b.rotation, atol=1e-12)
