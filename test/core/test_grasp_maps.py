# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""G and J from first principles: moments summed by hand, finite differences of kinematics."""

from grasp_torque_opt.core.exceptions import FrameNotFound
from grasp_torque_opt.core.grasp_maps import compute_grasp_maps
from grasp_torque_opt.core.scenario_fields import ContactSpec
import numpy as np
import pinocchio as pin
import pytest


def contact_point_and_rotation(setup, q, i):
    model = setup.hand.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    spec = setup.contacts[i]
    oMf = data.oMf[model.getFrameId(spec.link)]
    return oMf.act(spec.position), oMf.rotation.copy()


@pytest.mark.parametrize('name', ['planar', 'allegro'])
def test_jacobian_matches_finite_differences(name, request):
    setup = request.getfixturevalue(name)
    maps = setup.maps()
    h = 1e-7
    for i, frame in enumerate(maps.contacts):
        R = frame.rotation
        J_fd = np.zeros((4, setup.hand.m))
        for k, iq in enumerate(setup.hand.idx_q):
            qp, qm = setup.q.copy(), setup.q.copy()
            qp[iq] += h
            qm[iq] -= h
            pp, Rp = contact_point_and_rotation(setup, qp, i)
            pm, Rm = contact_point_and_rotation(setup, qm, i)
            omega = pin.log3(Rp @ Rm.T) / (2 * h)      # base axes
            J_fd[:3, k] = R.T @ (pp - pm) / (2 * h)
            J_fd[3, k] = R[:, 2] @ omega
        np.testing.assert_allclose(maps.J[4 * i:4 * i + 4], J_fd, atol=1e-7)


@pytest.mark.parametrize('name', ['planar', 'allegro'])
def test_grasp_matrix_sums_forces_and_moments(name, request):
    setup = request.getfixturevalue(name)
    maps = setup.maps()
    rng = np.random.default_rng(1)
    f = rng.normal(size=4 * maps.p)
    force, moment = np.zeros(3), np.zeros(3)
    for i, frame in enumerate(maps.contacts):
        fx, fy, fz, mz = f[4 * i:4 * i + 4]
        F = frame.rotation @ np.array([fx, fy, fz])
        force += F
        moment += np.cross(frame.position - maps.object_origin, F) + mz * frame.normal
    np.testing.assert_allclose(maps.G @ f, np.concatenate((force, moment)), atol=1e-12)


def test_contact_frames_follow_the_scenario(planar):
    maps = planar.maps()
    for spec, frame in zip(planar.contacts, maps.contacts):
        np.testing.assert_allclose(frame.normal, spec.normal / np.linalg.norm(spec.normal))
        np.testing.assert_allclose(frame.rotation.T @ frame.rotation, np.eye(3), atol=1e-12)


def test_default_normal_points_to_the_object_origin(planar):
    spec = ContactSpec(link='finger1_tip', position=np.zeros(3))
    maps = compute_grasp_maps(planar.hand, planar.q, [spec], planar.object_origin)
    d = planar.object_origin - maps.contacts[0].position
    np.testing.assert_allclose(maps.contacts[0].normal, d / np.linalg.norm(d))


def test_unknown_frame_is_named(planar):
    spec = ContactSpec(link='finger3_tip', position=np.zeros(3))
    with pytest.raises(FrameNotFound, match=r'grasp\.contacts\[0\]\.link: unknown frame '
                                            r"'finger3_tip' \(did you mean 'finger1_tip' or "
                                            r"'finger2_tip'.*model frames: finger1_distal"):
        compute_grasp_maps(planar.hand, planar.q, [spec], planar.object_origin)
