# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Whose collision shapes the planner reads: the hand's own links, or the whole URDF's.

The hand's links are checked against the URDF's own joint tree, read here with
ElementTree (not Pinocchio's model, which ``hand_links`` reads): on the G1 every link
below the right wrist's pitch joint, and nothing of the arm, the torso, the legs or the
left hand; on the Allegro, whose URDF is the hand, every link.
"""

import json
import xml.etree.ElementTree as ET

from conftest import ROOT
from grasp_torque_opt.cli import main
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.geometry_contacts import collision_model, hand_links
from grasp_torque_opt.core.grasp_setup import bind_for_candidates
from grasp_torque_opt.core.hand import resolve_urdf
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.methods.plan import PlanSettings
import pytest

G1 = ROOT / 'config' / 'g1_right.yaml'
ALLEGRO = ROOT / 'config' / 'allegro_right.yaml'


def bound(path):
    """Return (the hand the planner binds, its URDF file)."""
    scenario = load_scenario(path)
    setup, _ = bind_for_candidates(scenario)
    return setup.hand, resolve_urdf(scenario.urdf, scenario.base_dir)


def below(urdf, link: str) -> set[str]:
    """Return ``link`` and every link below it in the URDF's joint tree."""
    root = ET.parse(urdf).getroot()
    children: dict[str, list[str]] = {}
    for joint in root.iter('joint'):
        children.setdefault(joint.find('parent').get('link'), []).append(
            joint.find('child').get('link'))
    out, todo = set(), [link]
    while todo:
        name = todo.pop()
        out.add(name)
        todo += children.get(name, [])
    return out


def test_the_g1_hand_is_its_wrist_palm_and_fingers():
    hand, urdf = bound(G1)
    links = hand_links(hand)
    assert links == below(urdf, 'right_wrist_pitch_link')
    assert {'right_hand_palm_link', 'right_wrist_yaw_link'} <= links
    assert not links & {'torso_link', 'right_elbow_link', 'left_hand_palm_link', 'pelvis'}


def test_the_allegro_urdf_is_all_hand():
    hand, urdf = bound(ALLEGRO)
    root = ET.parse(urdf).getroot()
    assert hand_links(hand) == {link.get('name') for link in root.iter('link')}


def test_the_collision_model_reads_only_the_links_asked():
    hand, urdf = bound(G1)
    keep = hand_links(hand)
    model = hand.model
    few = {model.frames[g.parentFrame].name for g in
           collision_model(hand, urdf, links=keep).geometryObjects}
    every = {model.frames[g.parentFrame].name for g in
             collision_model(hand, urdf).geometryObjects}
    assert few == keep & every  # every hand link with a shape, nothing else
    assert 'torso_link' in every and 'torso_link' not in few


def test_the_g1_plans_the_same_candidates_from_its_hand_alone(tmp_path):
    out = {}
    for shapes in ('hand', 'robot'):
        path = tmp_path / f'{shapes}.jsonl'
        assert main(['plan', str(G1), '--count', '3', '--seed', '1', '--shapes', shapes,
                     '--out', str(path)]) == 0
        out[shapes] = [json.loads(line) for line in path.read_text().splitlines()]
    assert len(out['hand']) == 3
    assert out['hand'] == out['robot']


def test_a_bad_shapes_setting_is_named(capsys):
    with pytest.raises(InputError, match='shapes'):
        PlanSettings(shapes='arm')
    with pytest.raises(SystemExit):
        main(['plan', str(G1), '--shapes', 'arm'])
    assert "--shapes: invalid choice: 'arm'" in capsys.readouterr().err
