# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The pinned tangent rule of docs/design.md section 1."""

from grasp_torque_opt.core.contact_frame import contact_rotation
from grasp_torque_opt.core.exceptions import InputError
import numpy as np
import pytest


def check_rotation(R):
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0)


@pytest.mark.parametrize('normal,axis', [
    ([1, 0, 0], [0, 1, 0]),          # tie between e_y and e_z: the first, e_y
    ([0, 0, -1], [1, 0, 0]),
    ([0.2, 0.9, 0.1], [0, 0, 1]),
    ([-0.5, 0.3, 0.8], [0, 1, 0]),
])
def test_tangent_rule(normal, axis):
    R = contact_rotation(np.array(normal, float))
    check_rotation(R)
    z = np.array(normal, float) / np.linalg.norm(normal)
    x = np.cross(axis, z)
    np.testing.assert_allclose(R[:, 2], z, atol=1e-15)
    np.testing.assert_allclose(R[:, 0], x / np.linalg.norm(x), atol=1e-15)
    np.testing.assert_allclose(R[:, 1], np.cross(z, R[:, 0]), atol=1e-15)


def test_given_tangent_is_projected():
    R = contact_rotation(np.array([0, 0, 2.0]), tangent=np.array([1.0, 1.0, 5.0]))
    check_rotation(R)
    np.testing.assert_allclose(R[:, 0], np.array([1, 1, 0]) / np.sqrt(2))


def test_zero_normal_and_parallel_tangent_are_refused():
    with pytest.raises(InputError, match=r'c\[0\]\.normal: must be finite and not zero'):
        contact_rotation(np.zeros(3), field='c[0]')
    with pytest.raises(InputError, match=r'c\[1\]\.tangent: is parallel to the normal'):
        contact_rotation(np.array([0, 1.0, 0]), np.array([0, -3.0, 0]), field='c[1]')
