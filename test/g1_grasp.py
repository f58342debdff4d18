# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""A three-finger grasp of the Unitree G1's right Dex3-1 hand (example-robot-data)."""

G1 = 'example-robot-data:g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf'
PALM = 'right_hand_palm_link'
HAND_Q = {'right_hand_index_0_joint': 0.5, 'right_hand_index_1_joint': 0.6,
          'right_hand_middle_0_joint': 0.5, 'right_hand_middle_1_joint': 0.6,
          'right_hand_thumb_0_joint': 0.0, 'right_hand_thumb_1_joint': 0.3,
          'right_hand_thumb_2_joint': -0.6}
#: Another posture of the robot around the hand: waist, right arm and a leg.
ARM_Q = {'waist_yaw_joint': 0.4, 'waist_pitch_joint': 0.2, 'right_shoulder_pitch_joint': -0.8,
         'right_shoulder_roll_joint': -0.3, 'right_elbow_joint': 1.1,
         'right_wrist_roll_joint': 0.5, 'right_wrist_pitch_joint': -0.4,
         'left_knee_joint': 0.9}
LINKS = ['right_hand_index_1_link', 'right_hand_middle_1_link', 'right_hand_thumb_2_link']
#: The three contacts' centroid in the palm frame (their link origins at HAND_Q) [m].
ORIGIN = [0.0817507, 0.0345899, 0.0]


def g1_doc(base_link=PALM, posture=None):
    """Write a three-finger grasp of the G1's right Dex3-1 hand in ``base_link``'s frame."""
    hand = {'urdf': G1, 'joints': list(HAND_Q)}
    if base_link:
        hand['base_link'] = base_link
    return {'hand': hand,
            'grasp': {'joint_positions': {**HAND_Q, **(posture or {})},
                      'object_origin': list(ORIGIN),
                      'contacts': [{'link': link, 'position': [0.0, 0.0, 0.0]}
                                   for link in LINKS]},
            'friction': {'mu_tangential': 0.8, 'mu_torsional': 0.005, 'polygon_sides': 8,
                         'min_normal_force': 0.1},
            'load': {'external_wrench': [0.0, 0.3, -0.5, 0.01, 0.0, 0.0]}}
