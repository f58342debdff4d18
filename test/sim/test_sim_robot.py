# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Any URDF the solver accepts in MuJoCo: meshes, a welded robot, coupled joints."""

import copy
import re

from conftest import ALLEGRO, CONFIG, scenario_doc
from g1_grasp import ARM_Q, g1_doc, ORIGIN, PALM
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import example_robot_data_dir
from grasp_torque_opt.core.meshes import resolve_mesh
from grasp_torque_opt.core.scenario import load_scenario, parse_scenario
from grasp_torque_opt.sim.hold import certified_torques, hold, HoldSettings
from grasp_torque_opt.sim.model import build_model
from grasp_torque_opt.sim.simulator import HandSim
import mujoco
import numpy as np
import pinocchio as pin
import pytest

#: The Allegro's index, middle and ring distal joints coupled to their middle joints.
PAIRS = [('joint_3.0', 'joint_2.0'), ('joint_7.0', 'joint_6.0'), ('joint_11.0', 'joint_10.0')]


def test_package_urls_resolve_in_example_robot_data(tmp_path, monkeypatch):
    url = 'package://example-robot-data/robots/g1_description/meshes/pelvis.STL'
    assert resolve_mesh(url, None) == (example_robot_data_dir() / 'g1_description' /
                                       'meshes' / 'pelvis.STL')
    # A ROS package on ROS_PACKAGE_PATH, a relative path in the URDF's folder.
    (tmp_path / 'my_hand' / 'meshes').mkdir(parents=True)
    (tmp_path / 'my_hand' / 'meshes' / 'tip.stl').write_text('solid tip\nendsolid tip\n')
    monkeypatch.setenv('ROS_PACKAGE_PATH', str(tmp_path))
    monkeypatch.setenv('AMENT_PREFIX_PATH', '')
    assert resolve_mesh('package://my_hand/meshes/tip.stl', None) == \
        tmp_path / 'my_hand' / 'meshes' / 'tip.stl'
    assert resolve_mesh('meshes/tip.stl', tmp_path / 'my_hand') == \
        tmp_path / 'my_hand' / 'meshes' / 'tip.stl'
    with pytest.raises(InputError, match="mesh 'package://no_such/a.stl': package 'no_such' "
                                         'not found'):
        resolve_mesh('package://no_such/a.stl', None)


def g1_scenario():
    doc = g1_doc(posture=ARM_Q)
    doc['object'] = {'shape': 'sphere', 'size': [0.01], 'mass': 0.01, 'position': ORIGIN}
    doc['gravity'] = [0.0, 0.0, -9.81]
    del doc['load']
    return parse_scenario(doc, CONFIG)


def test_a_hand_inside_a_robot_is_simulated_with_the_robot_welded():
    scenario = g1_scenario()
    setup = GraspSetup.from_scenario(scenario)
    sim = build_model(scenario, setup=setup)
    assert sim.joints == tuple(setup.hand.joints)
    hinges = [sim.model.joint(j).name for j in range(sim.model.njnt)
              if sim.model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    assert sorted(hinges) == sorted(setup.hand.joints)  # the other 36 are welded
    hsim = HandSim(sim, setup.q[setup.hand.idx_q])
    data = setup.hand.model.createData()
    pin.framesForwardKinematics(setup.hand.model, data, setup.q)
    oMb = data.oMf[setup.hand.model.getFrameId(PALM)]
    palm = sim.model.body(PALM).id
    hsim.step(300)  # 0.3 s with no command: only welded joints would keep the palm there
    np.testing.assert_allclose(hsim.data.xpos[palm], oMb.translation, atol=1e-6)
    np.testing.assert_allclose(hsim.data.xmat[palm].reshape(3, 3), oMb.rotation, atol=1e-6)
    # The object is placed from the palm's frame.
    np.testing.assert_allclose(hsim.object_pose()[0], oMb.act(np.array(ORIGIN)), atol=1e-9)
    np.testing.assert_allclose(sim.model.opt.gravity, oMb.rotation @ [0.0, 0.0, -9.81])


def coupled_allegro():
    """Couple PAIRS of the bundled Allegro grasp at the grasp's ratios; also give it rigid."""
    doc = scenario_doc(ALLEGRO)
    q = doc['grasp']['joint_positions']
    actuators = [j for j in doc['hand']['joints'] if j not in dict(PAIRS)]
    rigid = copy.deepcopy(doc)
    rigid['hand']['joints'] = actuators
    doc['hand']['joints'] = actuators
    doc['hand']['coupling'] = {f: {'follows': t, 'multiplier': q[f] / q[t]} for f, t in PAIRS}
    for f, _ in PAIRS:
        del q[f]
    return parse_scenario(doc, CONFIG), parse_scenario(rigid, CONFIG)


def test_coupled_torques_hold_the_ball_and_the_rigid_share_drops_it():
    """
    Hold with the coupled optimum and drop with the rigid share (MuJoCo equalities).

    The rigid share: the same actuators solved as if the followers were locked (a
    coupling ignored), the command the issue saw. Impedance 0.1 N m/rad, the least the
    bundled grasp needs (docs/simulation.md), so the torques must do the holding.
    """
    scenario, rigid = coupled_allegro()
    setup, _, sol, _ = certified_torques(scenario)
    _, _, wrong, _ = certified_torques(rigid)
    assert np.max(np.abs(wrong.tau - sol.tau)) > 0.01
    settings = HoldSettings(kp=0.1, duration=1.0)
    sim = build_model(scenario, setup=setup)
    assert sim.model.neq == len(PAIRS)
    held = hold(scenario, settings)
    assert held.held, held.reason
    dropped = hold(scenario, settings, tau=wrong.tau)
    assert not dropped.held and dropped.max_drift > 0.01, dropped.reason


def test_the_bundled_ability_grasp_holds_with_actuator_torques_and_drops_with_the_rigid_share():
    """
    The issue's case on the real coupled hand: u = C^T tau holds, the q1 share drops.

    The rigid share: the URDF without its mimic tags, each q2 locked where the coupling
    puts it, the same six actuators solved: the command that ignored the coupling.
    """
    scenario = load_scenario(CONFIG / 'ability_right.yaml')
    setup, _, sol, _ = certified_torques(scenario)
    rigid_doc = scenario_doc(CONFIG / 'ability_right.yaml')
    model = setup.hand.model
    for f in ('Right_index_q2', 'Right_middle_q2', 'Right_ring_q2', 'Right_pinky_q2'):
        rigid_doc['grasp']['joint_positions'][f] = float(setup.q[model.joints[
            model.getJointId(f)].idx_q])
    xml = (example_robot_data_dir() / 'alex_description/urdf/alex_psyonic_hands.urdf')
    rigid_xml = re.sub(r'<mimic[^>]*/>', '', xml.read_text())
    _, _, wrong, _ = certified_torques(parse_scenario(rigid_doc, CONFIG), rigid_xml)
    # The coupled fingers need more than their q1 share (index and middle here).
    assert np.all(sol.tau[:2] > wrong.tau[:2] * 1.2)
    settings = HoldSettings(kp=0.1, duration=1.0)
    held = hold(scenario, settings)
    assert held.held, held.reason
    dropped = hold(scenario, settings, tau=wrong.tau)
    assert not dropped.held and dropped.max_drift > 0.01, dropped.reason
