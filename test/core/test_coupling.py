# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Coupled joints: URDF mimic tags, the prefix rule, hand.coupling and their errors."""

import copy
import xml.etree.ElementTree as ET

from conftest import ROOT, setup_from_doc
from grasp_torque_opt.cli import main
from grasp_torque_opt.core.coupling import urdf_mimics
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.hand import example_robot_data_dir, Hand
import numpy as np
import pinocchio as pin
import pytest
import yaml

ALEX = 'alex_description/urdf/alex_psyonic_hands.urdf'
RIGHT = ['Right_index_q1', 'Right_middle_q1', 'Right_ring_q1', 'Right_pinky_q1',
         'Right_thumb_q1', 'Right_thumb_q2']


@pytest.fixture(scope='module')
def alex_xml():
    return (example_robot_data_dir() / ALEX).read_text()


def test_the_alex_mimic_tags_name_joints_by_their_suffix(alex_xml):
    """The issue's fact: the tags say ``index_q1`` where the joint is ``Right_index_q1``."""
    tags = urdf_mimics(alex_xml)
    assert {(m.joint, m.target) for m in tags} >= {('Right_index_q2', 'index_q1'),
                                                   ('Left_index_q2', 'index_q1')}
    assert len(tags) == 8  # index, middle, ring, pinky per hand: the thumbs' q2 are motors
    with pytest.raises(ValueError, match='not in the kinematic tree'):
        pin.buildModelFromXML(alex_xml, mimic=True)


def test_the_prefix_rule_couples_each_q2_to_its_own_hands_q1(alex_xml):
    hand = Hand.from_urdf_string(alex_xml, RIGHT, 1.0, True)
    f = hand.coupling.followers
    assert f['Right_index_q2'].target == 'Right_index_q1'
    assert f['Left_pinky_q2'].target == 'Left_pinky_q1'
    assert f['Right_index_q2'].multiplier == pytest.approx(1.05851325)
    # The coupled Jacobian equals Pinocchio's mimic model's, once the targets are fixed.
    root = ET.fromstring(alex_xml)
    for joint in root.iter('joint'):
        tag = joint.find('mimic')
        if tag is not None:
            tag.set('joint', joint.get('name').split('_')[0] + '_' + tag.get('joint'))
    mimic = pin.buildModelFromXML(ET.tostring(root, encoding='unicode'), mimic=True)
    assert mimic.nv == hand.model.nv - 8
    q = hand.configuration({'Right_index_q1': 0.4, 'Right_middle_q1': 0.7})
    qm = pin.neutral(mimic)
    for j in range(1, mimic.njoints):
        if mimic.joints[j].nq == 1 and 'Mimic' not in mimic.joints[j].shortname():
            qm[mimic.joints[j].idx_q] = q[hand.model.joints[
                hand.model.getJointId(mimic.names[j])].idx_q]
    frame = 'Right_middle_L2'
    data, dm = hand.model.createData(), mimic.createData()
    Jf = pin.computeFrameJacobian(hand.model, data, q, hand.model.getFrameId(frame),
                                  pin.LOCAL_WORLD_ALIGNED)
    Jm = pin.computeFrameJacobian(mimic, dm, qm, mimic.getFrameId(frame),
                                  pin.LOCAL_WORLD_ALIGNED)
    cols = [mimic.joints[mimic.getJointId(n)].idx_v for n in RIGHT]
    np.testing.assert_allclose(Jf @ hand.velocity_map, Jm[:, cols], atol=1e-12)


def test_a_target_the_rule_cannot_resolve_is_refused_naming_both(alex_xml):
    xml = alex_xml.replace('joint = "index_q1"', 'joint = "dex_q1"')
    with pytest.raises(InputError, match="joint 'Left_index_q2' follows 'dex_q1', which is "
                                         'not a joint of the model'):
        Hand.from_urdf_string(xml, RIGHT, 1.0, True)


def test_the_cli_refuses_it_with_exit_2(alex_xml, tmp_path, planar_doc, capsys):
    bad = tmp_path / 'alex.urdf'
    bad.write_text(alex_xml.replace('joint = "middle_q1"', 'joint = "middle_q9"'))
    doc = copy.deepcopy(planar_doc)
    doc['hand'] = {'urdf': str(bad), 'joints': RIGHT, 'torque_limits': 1.0}
    doc['grasp']['joint_positions'] = {}
    path = tmp_path / 'scenario.yaml'
    path.write_text(yaml.safe_dump(doc))
    assert main(['solve', str(path)]) == 2
    err = capsys.readouterr().err
    assert "hand.urdf: joint 'Left_middle_q2' follows 'middle_q9'" in err


def test_a_follower_listed_as_actuated_is_refused(alex_xml):
    with pytest.raises(InputError, match=r"hand.joints\[6\]: 'Right_index_q2' follows "
                                         r"'Right_index_q1' \(coupled in the URDF\): list its "
                                         "actuator 'Right_index_q1' only"):
        Hand.from_urdf_string(alex_xml, RIGHT + ['Right_index_q2'], 1.0, True)


def test_a_follower_takes_its_position_from_the_coupling(alex_xml):
    hand = Hand.from_urdf_string(alex_xml, RIGHT, 1.0, True)
    q = hand.configuration({'Right_ring_q1': 0.5})
    iq = hand.model.joints[hand.model.getJointId('Right_ring_q2')].idx_q
    assert q[iq] == pytest.approx(1.05851325 * 0.5 + 0.72349796)
    hand.configuration({'Right_ring_q1': 0.5, 'Right_ring_q2': float(q[iq])})
    with pytest.raises(InputError, match=r'grasp.joint_positions.Right_ring_q2: is 0, but '
                                         r"'Right_ring_q2' = 1.05851 \* 'Right_ring_q1' "
                                         r'\+ 0.723498 = 1.25275'):
        hand.configuration({'Right_ring_q1': 0.5, 'Right_ring_q2': 0.0})


def test_a_robot_without_hand_joints_is_refused(alex_xml):
    with pytest.raises(InputError, match='hand.joints: required: the model has 31 one-DoF '
                                         'joints, more than a hand'):
        Hand.from_urdf_string(alex_xml, None, 1.0, True)
    hand = Hand.from_urdf_string(alex_xml, None, 1.0, True,
                                 base_link='RightPsyonicAbilityBaseLink')
    assert sorted(hand.joints) == sorted(RIGHT)


@pytest.mark.parametrize('coupling, field, problem', [
    ([], 'hand.coupling', 'must be a mapping'),
    ({'joint2': {'follows': 'joint1', 'ratio': 2}}, 'hand.coupling.joint2.ratio',
     'unknown field'),
    ({'joint2': {'multiplier': 2}}, 'hand.coupling.joint2.follows', 'missing required field'),
    ({'joint2': {'follows': 'joint9'}}, 'hand.coupling.joint2',
     "joint 'joint2' follows 'joint9', which is not a joint"),
    ({'joint2': {'follows': 'joint2'}}, 'hand.coupling.joint2', 'follows itself'),
    ({'joint2': {'follows': 'joint4'}, 'joint4': {'follows': 'joint2'}}, 'hand.coupling',
     'in a cycle'),
])
def test_bad_coupling_names_its_field(planar_doc, coupling, field, problem):
    doc = copy.deepcopy(planar_doc)
    doc['hand']['coupling'] = coupling
    doc['hand']['joints'] = ['joint1', 'joint3']
    doc['hand']['torque_limits'] = 5.0
    with pytest.raises(InputError, match=problem) as e:
        setup_from_doc(doc)
    assert e.value.field.startswith(field)


def test_bundled_urdf_dir_exists():
    assert (ROOT / 'urdf').is_dir()
