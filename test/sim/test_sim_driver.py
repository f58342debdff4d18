# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""grasp-torque-sim with the real node over real ROS topics (processes, own ROS domain)."""

import os
import re
import subprocess
import sys

import pytest
from ros_harness import DOMAIN


def run(*args, timeout=120):
    env = dict(os.environ, ROS_DOMAIN_ID=str(DOMAIN), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    # As a user starts it: MuJoCo's GL backend not chosen beforehand (this process may have
    # set it by importing grasp_torque_opt.sim).
    env.pop('MUJOCO_GL', None)
    return subprocess.run([sys.executable, '-m', 'grasp_torque_opt.ros.sim_driver', *args],
                          capture_output=True, text=True, timeout=timeout, env=env)


def test_the_nodes_torques_hold_the_ball_over_ros(tmp_path):
    picture = tmp_path / 'grasp.png'
    done = run('--with-node', '--duration', '1.5', '--contacts', '--picture', str(picture))
    assert done.returncode == 0, done.stdout + done.stderr
    summary = next(line for line in done.stdout.splitlines() if line.startswith('summary: '))
    assert summary.startswith('summary: held: drift '), summary
    drift = float(re.search(r'drift ([0-9.]+) mm', summary).group(1))
    assert drift < 1.0
    # The forces MuJoCo measures are the ones the node predicted, within a few percent.
    error = float(re.search(r'contact forces within ([0-9.]+)%', summary).group(1))
    assert error < 3.0, summary
    commands = int(re.search(r'; (\d+) commands', summary).group(1))
    assert commands > 100  # 1.5 s at 250 joint states a second
    assert picture.read_bytes()[:4] == b'\x89PNG'


@pytest.mark.parametrize('params', ['g1_right_node.yaml', 'ability_right_node.yaml'])
def test_a_hand_inside_its_robot_holds_the_ball_through_the_node(params):
    """The bundled G1 and Ability grasps: robot welded, base link's frame, contacts fed back."""
    done = run('--with-node', '--params', params, '--duration', '1.5', '--kp', '0.1',
               '--contacts', '--no-picture')
    assert done.returncode == 0, done.stdout + done.stderr
    summary = next(line for line in done.stdout.splitlines() if line.startswith('summary: '))
    assert summary.startswith('summary: held: drift '), summary
    assert float(re.search(r'drift ([0-9.]+) mm', summary).group(1)) < 1.0


def test_bad_arguments_give_one_line_and_exit_2():
    done = run('--kp', '-1', timeout=60)
    assert done.returncode == 2 and done.stdout == ''
    assert done.stderr == 'grasp-torque-sim: error: --kp: must be >= 0\n'
    done = run('--params', 'no_such_params.yaml', timeout=60)
    assert done.returncode == 2 and len(done.stderr.splitlines()) == 1
    assert done.stderr.startswith('grasp-torque-sim: error: --params: file not found')
