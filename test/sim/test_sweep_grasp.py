# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The sweep IK and the bundled G1 grasp it made: on the ball, within limits, held."""

import copy

from conftest import CONFIG, scenario_doc
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.scenario import load_scenario, parse_scenario
from grasp_torque_opt.sim.hold import hold, HoldSettings
from grasp_torque_opt.sim.sweep_grasp import sweep_grasp
import numpy as np
import pytest

G1_RIGHT = CONFIG / 'g1_right.yaml'
#: The closed poses the bundled grasp was swept towards (within the URDF limits).
CLOSED = {'right_hand_index_1_link': {'right_hand_index_0_joint': 1.5,
                                      'right_hand_index_1_joint': 1.7},
          'right_hand_middle_1_link': {'right_hand_middle_0_joint': 1.5,
                                       'right_hand_middle_1_joint': 1.7},
          'right_hand_thumb_2_link': {'right_hand_thumb_0_joint': 0.0,
                                      'right_hand_thumb_1_joint': -0.5,
                                      'right_hand_thumb_2_joint': -1.7}}


def unswept(doc):
    doc = copy.deepcopy(doc)
    doc['grasp']['joint_positions'] = {}
    for contact in doc['grasp']['contacts']:
        contact.pop('position', None)
    return doc


def test_the_sweep_makes_the_bundled_g1_grasp_again():
    bundled = scenario_doc(G1_RIGHT)
    made = sweep_grasp(unswept(bundled), CONFIG, CLOSED)
    assert made['grasp']['joint_positions'] == pytest.approx(bundled['grasp']['joint_positions'],
                                                             abs=1e-4)
    for a, b in zip(made['grasp']['contacts'], bundled['grasp']['contacts']):
        assert a['link'] == b['link']
        np.testing.assert_allclose(a['position'], b['position'], atol=2e-5)


def test_the_bundled_g1_grasp_is_on_the_ball_within_limits():
    scenario = load_scenario(G1_RIGHT)
    setup = GraspSetup.from_scenario(scenario)
    hand = setup.hand
    q = setup.q[hand.idx_q]
    assert np.all(q >= hand.model.lowerPositionLimit[hand.idx_q])
    assert np.all(q <= hand.model.upperPositionLimit[hand.idx_q])
    maps = setup.maps()
    radius = scenario.object.size[0]
    distances = np.linalg.norm(maps.positions - scenario.object_origin, axis=1)
    np.testing.assert_allclose(distances, radius, atol=1e-4)
    assert maps.positions.shape == (3, 3)


def test_a_finger_that_closes_without_touching_is_named():
    doc = unswept(scenario_doc(G1_RIGHT))
    doc['grasp']['object_origin'] = doc['object']['position'] = [0.3, 0.3, 0.0]
    with pytest.raises(InputError, match='grasp.contacts: .*closed without touching'):
        sweep_grasp(doc, CONFIG, CLOSED)


def test_the_bundled_g1_grasp_holds_its_ball_with_its_torques_only():
    scenario = load_scenario(G1_RIGHT)
    held = hold(scenario, HoldSettings(kp=0.1, duration=1.0))
    assert held.held, held.reason
    dropped = hold(scenario, HoldSettings(kp=0.1, duration=1.0, feedforward=0.0))
    assert not dropped.held, dropped.reason


def test_the_sweep_moves_coupled_joints_with_their_actuators():
    """On the Ability hand (URDF mimic tags), the contacts found lie on the ball."""
    doc = {'hand': {'urdf': 'example-robot-data:alex_description/urdf/alex_psyonic_hands.urdf',
                    'base_link': 'RightPsyonicAbilityBaseLink'},
           'grasp': {'object_origin': [-0.025, 0.04, 0.1],
                     'contacts': [{'link': 'Right_thumb_L2'}, {'link': 'Right_index_L2'}]},
           'friction': {'mu_tangential': 1.0, 'mu_torsional': 0.005, 'polygon_sides': 8},
           'object': {'shape': 'sphere', 'size': [0.025], 'mass': 0.1},
           'gravity': [0.0, 0.0, -9.81]}
    closed = {'Right_index_L2': {'Right_index_q1': 2.0},
              'Right_thumb_L2': {'Right_thumb_q1': -1.3, 'Right_thumb_q2': 1.5}}
    made = sweep_grasp(doc, CONFIG, closed)
    assert 'Right_index_q2' not in made['grasp']['joint_positions']  # it follows
    setup = GraspSetup.from_scenario(parse_scenario(made, CONFIG))
    distances = np.linalg.norm(setup.maps().positions - [-0.025, 0.04, 0.1], axis=1)
    np.testing.assert_allclose(distances, 0.025, atol=1e-4)


def test_the_sweep_makes_the_bundled_ability_grasp_again():
    bundled = scenario_doc(CONFIG / 'ability_right.yaml')
    closed = {'Right_index_L2': {'Right_index_q1': 2.0},
              'Right_middle_L2': {'Right_middle_q1': 2.0},
              'Right_thumb_L2': {'Right_thumb_q1': -1.3, 'Right_thumb_q2': 1.5}}
    made = sweep_grasp(unswept(bundled), CONFIG, closed)
    assert made['grasp']['joint_positions'] == pytest.approx(bundled['grasp']['joint_positions'],
                                                             abs=1e-4)
    for a, b in zip(made['grasp']['contacts'], bundled['grasp']['contacts']):
        np.testing.assert_allclose(a['position'], b['position'], atol=2e-5)
