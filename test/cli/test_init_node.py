# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
``grasp-torque-opt init-node``: a params file from the scenario alone drives the real node.

The newcomer's case of docs/your-hand.md: a 6-joint hand (the Ability scenario, copied
as one's own) with the Allegro's params file fails at start-up; init-node's file holds
the ball in the simulated hand over ROS.
"""

import os
from pathlib import Path
import re
import subprocess
import sys

from conftest import CONFIG
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.hand import resolve_urdf
import numpy as np
import pinocchio as pin
import pytest
from ros_harness import PROCESS_DOMAIN
import yaml

SCENARIOS = ['allegro_right.yaml', 'g1_right.yaml', 'ability_right.yaml',
             'planar_two_finger.yaml']


def cli(*args, cwd, timeout=120):
    done = subprocess.run([sys.executable, '-m', 'grasp_torque_opt.cli', *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, cwd=cwd)
    return done.returncode, done.stdout, done.stderr


def sim(*args, cwd, timeout=180):
    env = dict(os.environ, ROS_DOMAIN_ID=str(PROCESS_DOMAIN),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    env.pop('MUJOCO_GL', None)
    return subprocess.run([sys.executable, '-m', 'grasp_torque_opt.ros.sim_driver', *args],
                          capture_output=True, text=True, timeout=timeout, env=env, cwd=cwd)


def urdf_limits(doc: dict, base: Path) -> np.ndarray:
    """Return the effort limits Pinocchio reads from the URDF, in the scenario's joint order."""
    try:
        path = resolve_urdf(doc['hand']['urdf'], base)
    except InputError:
        path = doc['hand']['urdf']
    model = pin.buildModelFromUrdf(str(path))
    return np.array([model.effortLimit[model.joints[model.getJointId(j)].idx_v]
                     for j in doc['hand']['joints']])


@pytest.mark.parametrize('name', SCENARIOS)
def test_the_file_has_the_scenarios_joints_and_limits(tmp_path, name):
    code, out, err = cli('init-node', CONFIG / name, '--out', tmp_path / 'hand_node.yaml',
                         cwd=tmp_path)
    assert code == 0, err
    params = yaml.safe_load((tmp_path / 'hand_node.yaml').read_text())['/**']['ros__parameters']
    doc = yaml.safe_load((CONFIG / name).read_text())
    joints = doc['hand']['joints']
    given = doc['hand'].get('torque_limits')
    limits = (np.array(given, dtype=float) if given is not None
              else urdf_limits(doc, CONFIG))
    assert np.allclose(params['torque_limits'], limits, rtol=1e-6)
    assert all(isinstance(v, float) for v in params['torque_limits'])  # ROS doubles
    assert params['gravity_compensation'] is (doc.get('gravity') is not None)
    assert params['imu'] == {'enabled': False}
    assert Path(params['scenario']).resolve() == (CONFIG / name).resolve()
    controllers = yaml.safe_load((tmp_path / 'hand_controllers.yaml').read_text())
    assert controllers['effort_controller']['ros__parameters']['joints'] == joints
    assert f'({len(joints)} joints' in out


def test_another_hands_file_fails_with_the_nodes_own_error_and_init_nodes_holds(tmp_path):
    (tmp_path / 'my_hand.yaml').write_text((CONFIG / 'ability_right.yaml').read_text())
    allegro = (CONFIG / 'allegro_right_node.yaml').read_text()
    copied = re.sub(r'scenario: allegro_right.yaml .*', 'scenario: my_hand.yaml', allegro)
    (tmp_path / 'copied_node.yaml').write_text(copied)
    done = sim('--params', 'copied_node.yaml', '--with-node', '--no-picture', '--duration',
               '0.5', cwd=tmp_path)
    assert done.returncode == 1
    said = done.stderr.strip().splitlines()[-1]
    assert said == ('grasp-torque-sim: grasp_torque_node exited with code 2 at start-up: '
                    'error: torque_limits: must have 6 entries, got 16'), done.stderr

    code, out, err = cli('init-node', 'my_hand.yaml', '--out', 'my_hand_node.yaml',
                         cwd=tmp_path)
    assert code == 0, err
    assert 'scenario: my_hand.yaml ' in (tmp_path / 'my_hand_node.yaml').read_text()
    done = sim('--params', 'my_hand_node.yaml', '--with-node', '--no-picture', '--duration',
               '1.0', cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert 'summary: held: drift ' in done.stdout


def test_bad_input_exits_2_and_writes_nothing(tmp_path):
    out = tmp_path / 'node.yaml'
    code, _, err = cli('init-node', 'no_such.yaml', '--out', out, cwd=tmp_path)
    assert code == 2 and 'scenario' in err and 'file not found' in err
    assert not out.exists()
    out.write_text('mine\n')
    code, _, err = cli('init-node', CONFIG / 'planar_two_finger.yaml', '--out', out,
                       cwd=tmp_path)
    assert code == 2 and err.strip().endswith(f'--out: {out} exists (--force overwrites it)')
    assert out.read_text() == 'mine\n' and not (tmp_path / 'node_controllers.yaml').exists()
    code, _, err = cli('init-node', CONFIG / 'planar_two_finger.yaml', '--out', out, '--force',
                       cwd=tmp_path)
    assert code == 0, err
    code, _, err = cli('init-node', CONFIG / 'planar_two_finger.yaml', '--out',
                       tmp_path / 'missing' / 'a.yaml', cwd=tmp_path)
    assert code == 2 and 'no such folder' in err
