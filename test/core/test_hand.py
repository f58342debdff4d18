# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Loading hands: paths, example-robot-data, joints and limits."""

import re

from conftest import ALLEGRO_URDF, ROOT
from grasp_torque_opt.core.exceptions import InputError, JointNotFound
from grasp_torque_opt.core.hand import example_robot_data_dir, Hand, resolve_urdf
import numpy as np
import pytest


def test_example_robot_data_allegro():
    path = resolve_urdf(ALLEGRO_URDF, ROOT)
    assert path.is_file() and path.is_relative_to(example_robot_data_dir())
    hand = Hand.from_urdf(path)
    assert hand.m == 16 and hand.joints[0] == 'joint_0.0'
    np.testing.assert_allclose(hand.torque_limits, hand.model.effortLimit[hand.idx_v])


def test_relative_and_missing_paths():
    assert resolve_urdf('urdf/planar_two_finger.urdf', ROOT).is_file()
    with pytest.raises(InputError, match='hand.urdf: file not found'):
        resolve_urdf('example-robot-data:nope/none.urdf', ROOT)


def test_joint_order_is_command_order():
    hand = Hand.from_urdf(ROOT / 'urdf/planar_two_finger.urdf', ['joint3', 'joint1'], 2.0)
    assert hand.joints == ['joint3', 'joint1']
    assert list(hand.idx_v) == [hand.model.joints[hand.model.getJointId(n)].idx_v
                                for n in ('joint3', 'joint1')]
    np.testing.assert_array_equal(hand.torque_limits, [2.0, 2.0])


def test_fixed_joint_is_not_actuated():
    with pytest.raises(JointNotFound, match=r'hand.joints\[0\]: unknown joint '
                                            r"'finger1_tip_joint' \(1-DoF joints: joint1"):
        Hand.from_urdf(ROOT / 'urdf/planar_two_finger.urdf', ['finger1_tip_joint'])


def test_urdf_string_is_parsed():
    hand = Hand.from_urdf_string((ROOT / 'urdf/planar_two_finger.urdf').read_text())
    assert hand.joints == ['joint1', 'joint2', 'joint3', 'joint4']
    np.testing.assert_array_equal(hand.torque_limits, [10, 5, 10, 5])
    with pytest.raises(InputError, match='robot_description: cannot parse'):
        Hand.from_urdf_string("<robot name='x'><link name='a'/><joint/></robot>")


def test_limits_above_the_urdf_effort_are_refused_unless_allowed():
    urdf = ROOT / 'urdf/planar_two_finger.urdf'  # effort limits 10, 5, 10, 5 N m
    with pytest.raises(InputError, match=r"^hand.torque_limits: 6 N m for joint 'joint2' "
                       r'exceeds the URDF effort limit \(5 N m\); set '
                       r'hand.torque_limits_above_urdf: true to allow it$'):
        Hand.from_urdf(urdf, None, [10.0, 6.0, 10.0, 5.0])
    hand = Hand.from_urdf(urdf, None, [10.0, 6.0, 10.0, 5.0], above_urdf=True)
    np.testing.assert_array_equal(hand.torque_limits, [10.0, 6.0, 10.0, 5.0])
    np.testing.assert_array_equal(hand.effort_limits, [10.0, 5.0, 10.0, 5.0])
    with pytest.raises(InputError, match=r'exceeds the largest limit accepted \(10000 N m\)'):
        Hand.from_urdf(urdf, None, 1e300, above_urdf=True)


def test_pinocchio_orders_joints_unlike_the_urdf_file():
    """
    Pinocchio orders joints unlike the URDF file: why per-joint lists need hand.joints.

    The Allegro's model order is 0-3, 12-15, 4-7, 8-11, not the file's 0-15.
    """
    hand = Hand.from_urdf(resolve_urdf(ALLEGRO_URDF, ROOT))
    assert [int(float(n.split('_')[1])) for n in hand.joints] == \
        [0, 1, 2, 3, 12, 13, 14, 15, 4, 5, 6, 7, 8, 9, 10, 11]


def test_urdfdoms_own_lines_stay_off_the_terminal(capfd):
    # A limit without effort: urdfdom prints "Error: ... joint.cpp" on fd 2 before
    # Pinocchio raises; the InputError alone tells the user.
    xml = re.sub(r'effort="[^"]*"', '', (ROOT / 'urdf' / 'planar_two_finger.urdf').read_text())
    with pytest.raises(InputError, match='robot_description'):
        Hand.from_urdf_string(xml)
    assert capfd.readouterr().err == ''
