# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The message checks as pure functions: each returns the checked values or names the field."""

from grasp_torque_opt.control.checks import (
    check_joint_names,
    checked_gravity,
    checked_wrench,
    contact_rotations,
    quaternion_matrix,
    show,
    SHOWN_NAME_LENGTH,
)
from grasp_torque_opt.control.parameters.generated import CycleConfig
from grasp_torque_opt.control.parameters.limits import MAX_GRAVITY
from grasp_torque_opt.core.exceptions import InputError
import numpy as np
import pytest


def model_joints(setup):
    model = setup.hand.model
    return {model.names[j]: model.joints[j].idx_q
            for j in range(1, model.njoints) if model.joints[j].nq == 1}


def test_names_are_checked_and_positions_written(planar):
    joints = planar.hand.joints
    names = ['extra', *joints]
    q = planar.q.copy()
    positions = [float('nan'), *[0.1 * (k + 1) for k in range(len(joints))]]
    kept = check_joint_names(names, positions, q, model_joints(planar), joints)
    assert kept[0] == names and kept[3] is joints
    np.testing.assert_allclose(q[kept[2]], positions[1:])
    assert list(kept[1]) == list(range(1, len(names)))


@pytest.mark.parametrize('names, positions, match', [
    (['a'], [], '1 names but 0 positions'),
    (['a', 'a'], [0.0, 0.0], "duplicate joint name 'a'"),
    ([''], [0.0], 'empty joint name'),
    (['a'], [0.0], 'missing commanded joint'),
])
def test_bad_names_name_the_problem(planar, names, positions, match):
    with pytest.raises(InputError, match=match):
        check_joint_names(names, positions, planar.q.copy(), model_joints(planar),
                          planar.hand.joints)


def test_a_used_position_beyond_the_bound_is_refused(planar):
    joints = planar.hand.joints
    positions = [0.0] * len(joints)
    positions[0] = 1e4
    with pytest.raises(InputError, match=f"position of '{joints[0]}' is 10000, beyond"):
        check_joint_names(list(joints), positions, planar.q.copy(), model_joints(planar),
                          joints)


def test_contact_rotations_check_shape_frame_and_quaternions(planar):
    p = len(planar.contacts)
    model = planar.hand.model
    quats = np.tile([0.0, 0.0, 0.0, 1.0], (p, 1))
    rotations = contact_rotations(model, p, '', np.zeros((p, 3)), quats)
    np.testing.assert_allclose(rotations, np.tile(np.eye(3), (p, 1, 1)))
    with pytest.raises(InputError, match=rf'expected \({p}, 3\) and \({p}, 4\)'):
        contact_rotations(model, p, '', np.zeros((p + 1, 3)), quats)
    with pytest.raises(InputError, match='contacts.header.frame_id'):
        contact_rotations(model, p, 'no_such_frame', np.zeros((p, 3)), quats)
    with pytest.raises(InputError, match=r'contacts.poses\[0\].orientation: is not a unit'):
        contact_rotations(model, p, '', np.zeros((p, 3)), 2 * quats)


def test_quaternion_near_unit_is_normalized():
    R = quaternion_matrix(np.array([0.0, 0.0, 0.0, 1.0005]), 'q')
    np.testing.assert_allclose(R, np.eye(3))


def test_wrench_bounds_name_the_part(planar):
    config = CycleConfig(max_wrench_force=10.0, max_wrench_torque=1.0)
    model = planar.hand.model
    limits = config.max_wrench_force, config.max_wrench_torque
    w = checked_wrench(model, '', [1.0, 2.0, 3.0], [0.1, 0.2, 0.3], *limits)
    np.testing.assert_allclose(w, [1.0, 2.0, 3.0, 0.1, 0.2, 0.3])
    with pytest.raises(InputError, match='external_wrench.wrench.force: norm 11 N exceeds'):
        checked_wrench(model, '', [11.0, 0.0, 0.0], [0.0, 0.0, 0.0], *limits)
    with pytest.raises(InputError, match='external_wrench.wrench.torque: norm 2 N m'):
        checked_wrench(model, '', [0.0, 0.0, 0.0], [0.0, 2.0, 0.0], *limits)
    with pytest.raises(InputError, match='external_wrench.wrench.force: must be finite'):
        checked_wrench(model, '', [np.nan, 0.0, 0.0], [0.0, 0.0, 0.0], *limits)


def test_gravity_is_turned_to_base_axes_and_bounded():
    flip = np.diag([1.0, -1.0, -1.0])
    np.testing.assert_allclose(checked_gravity('base', 'imu', [0.0, 0.0, 9.81], flip, ''),
                               [0.0, 0.0, -9.81])
    with pytest.raises(InputError, match="'imu' is not the hand's base frame 'base'.*why"):
        checked_gravity('base', 'imu', [0.0, 0.0, 9.81], None, 'why')
    with pytest.raises(InputError, match=f'exceeds {MAX_GRAVITY:g} m/s'):
        checked_gravity('base', '', [0.0, 0.0, 2 * MAX_GRAVITY], None, '')


def test_long_names_are_cut():
    assert show('a' * (SHOWN_NAME_LENGTH + 5)) == 'a' * SHOWN_NAME_LENGTH + '...'
    assert show('short') == 'short'
