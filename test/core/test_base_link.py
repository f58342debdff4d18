# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""A hand inside a robot: hand.base_link, the locked rest of the robot, the size bounds."""

import copy

from conftest import setup_from_doc
from g1_grasp import ARM_Q, g1_doc, HAND_Q, ORIGIN, PALM
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.hand import Hand, MAX_MODEL_DOF
from grasp_torque_opt.methods.dispatch import solve
from independent import assert_holds
import numpy as np
import pinocchio as pin
import pytest


def test_the_torques_do_not_depend_on_the_rest_of_the_robot():
    still = setup_from_doc(g1_doc())
    moved = setup_from_doc(g1_doc(posture=ARM_Q))
    assert still.hand.m == 7 and still.hand.base_frame == PALM
    a, b = solve(still), solve(moved)
    assert a.optimal and b.optimal
    assert_holds(moved, moved.maps(), b.tau, b.wrenches)
    np.testing.assert_allclose(b.tau, a.tau, atol=1e-9)
    np.testing.assert_allclose(moved.maps().positions, still.maps().positions, atol=1e-12)


def test_the_root_frame_scenario_of_one_posture_is_the_base_link_one_there():
    """Written in the pelvis at ARM_Q, the grasp gives the same torques; not at another pose."""
    at_arm = setup_from_doc(g1_doc(posture=ARM_Q))
    model = at_arm.hand.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, at_arm.q)
    oMb = data.oMf[model.getFrameId(PALM)]
    doc = g1_doc(base_link=None, posture=ARM_Q)
    doc['grasp']['object_origin'] = oMb.act(np.array(ORIGIN)).tolist()
    w = np.array(doc['load']['external_wrench'])
    doc['load']['external_wrench'] = np.concatenate((oMb.rotation @ w[:3],
                                                     oMb.rotation @ w[3:])).tolist()
    # The tangent rule picks x_i from the base axes: give the palm-frame tangents, turned.
    for contact, R in zip(doc['grasp']['contacts'], at_arm.maps().rotations):
        contact['tangent'] = (oMb.rotation @ R[:, 0]).tolist()
    in_root = setup_from_doc(doc)
    assert in_root.hand.base_frame == 'pelvis'
    np.testing.assert_allclose(solve(in_root).tau, solve(at_arm).tau, atol=1e-9)
    # Without hand.base_link the same numbers mean another grasp once the arm moves.
    doc['grasp']['joint_positions'] = dict(HAND_Q)
    other = solve(setup_from_doc(doc))
    assert not other.optimal or np.max(np.abs(other.tau - solve(at_arm).tau)) > 1e-3


def test_without_hand_joints_a_robot_is_refused_and_a_base_link_picks_its_hand():
    doc = g1_doc(base_link=None)
    del doc['hand']['joints']
    with pytest.raises(InputError, match='hand.joints: required: the model has 43 one-DoF'):
        setup_from_doc(doc)
    doc['hand']['base_link'] = PALM
    assert sorted(setup_from_doc(doc).hand.joints) == sorted(HAND_Q)


def test_a_joint_above_the_base_link_is_refused():
    doc = g1_doc()
    doc['hand']['joints'] = list(HAND_Q) + ['right_wrist_yaw_joint']
    with pytest.raises(InputError, match='hand.joints\\[7\\]: joint .right_wrist_yaw_joint. '
                                         'does not move below hand.base_link'):
        setup_from_doc(doc)


def test_an_unknown_base_link_names_close_frames():
    doc = g1_doc(base_link='right_hand_palm')
    with pytest.raises(InputError, match='hand.base_link') as e:
        setup_from_doc(doc)
    assert PALM in str(e.value)


def chain_urdf(n):
    """Write a chain of n revolute joints (a robot bigger than the old 64-DoF bound)."""
    links = ''.join(f'<link name="l{i}"><inertial><mass value="0.1"/><inertia ixx="1e-4" '
                    'ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>'
                    for i in range(n + 1))
    joints = ''.join(f'<joint name="j{i}" type="revolute"><parent link="l{i}"/>'
                     f'<child link="l{i + 1}"/><origin xyz="0 0 0.01"/><axis xyz="0 1 0"/>'
                     '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
                     for i in range(n))
    return f'<robot name="chain">{links}{joints}</robot>'


def test_the_size_bound_counts_the_hands_joints():
    xml = chain_urdf(80)
    hand = Hand.from_urdf_string(xml, ['j78', 'j79'], base_link='l78')
    assert hand.m == 2 and hand.model.nv == 80
    with pytest.raises(InputError, match=f'more than {MAX_MODEL_DOF}'):
        Hand.from_urdf_string(xml, [f'j{i}' for i in range(MAX_MODEL_DOF + 1)])
    doc = copy.deepcopy(g1_doc())
    assert setup_from_doc(doc).hand.model.nv == 43
