# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The node's executables refuse bad ROS arguments with one line and exit code 2.

rcl parses a params file and the remap rules, and rclpy checks a ``-p`` value
against the parameter's declared range and type, before the node's own checks
run: each used to end in rclpy's traceback.
"""

import os
from pathlib import Path
import subprocess
import sys

from conftest import CONFIG
import pytest
from ros_harness import DOMAIN

PARAMS = str(CONFIG / 'allegro_right_node.yaml')
CASES = {
    'params file that does not exist': (['--params-file', 'no_such_params.yaml'],
                                        "Couldn't parse params file"),
    'value out of the declared range': (['--params-file', PARAMS,
                                         '-p', 'mu_tangential:=100.0'],
                                        'mu_tangential out of range'),
    'value of the wrong type': (['--params-file', PARAMS, '-p', 'polygon_sides:=hello'],
                                "parameter 'polygon_sides'"),
    'unparsable node name': (['--params-file', PARAMS, '-r', '__node:=bad-name'],
                             "Couldn't parse remap rule"),
}


#: The managed node declares the scenario's parameters without values and checks them in
#: configure (test_lifecycle.py), so only rcl's own argument errors apply to it here.
RUNS = [('grasp_torque_opt.ros.node', case) for case in sorted(CASES)] + [
    ('grasp_torque_opt.ros.lifecycle_node', case) for case in sorted(CASES)
    if case in ('params file that does not exist', 'unparsable node name')]


@pytest.mark.parametrize(('module', 'case'), RUNS)
def test_bad_ros_arguments_give_one_line_and_exit_2(module, case, tmp_path: Path):
    args, expected = CASES[case]
    env = dict(os.environ, ROS_DOMAIN_ID=str(DOMAIN), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    proc = subprocess.run([sys.executable, '-m', module, '--ros-args', *args], env=env,
                          cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2, proc.stderr
    assert 'Traceback' not in proc.stderr, proc.stderr
    errors = [line for line in proc.stderr.splitlines() if ': error: ' in line]
    assert len(errors) == 1 and expected in errors[0], proc.stderr
