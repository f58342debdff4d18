# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""MuJoCo is optional: the core, the node and the CLI run without it; the sim says so."""

import subprocess
import sys

from conftest import ALLEGRO
from ros_domains import domain

BLOCK = "import sys\nsys.modules['mujoco'] = None\n"


def run(script):
    return subprocess.run([sys.executable, '-c', BLOCK + script], capture_output=True,
                          text=True, timeout=120)


def test_core_node_and_cli_run_without_mujoco():
    done = run(f"""
import rclpy
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.methods import solve
from grasp_torque_opt.ros.node import GraspTorqueNode
from grasp_torque_opt.cli import main
from rclpy.parameter import Parameter
assert solve(GraspSetup.from_file({str(ALLEGRO)!r})).optimal
rclpy.init(domain_id={domain('without_mujoco')})
node = GraspTorqueNode(parameter_overrides=[Parameter("scenario", value={str(ALLEGRO)!r})])
assert list(node.get_parameter("gravity").value) == [9.81, 0.0, 0.0]
node.destroy_node()
rclpy.shutdown()
assert main(["solve", {str(ALLEGRO)!r}]) == 0
assert "mujoco" not in [m for m in sys.modules if sys.modules[m] is not None]
""")
    assert done.returncode == 0, done.stderr


def test_the_simulated_hand_says_mujoco_is_missing():
    done = run('from grasp_torque_opt.ros.sim_driver import main\nsys.exit(main([]))')
    assert done.returncode == 2
    assert done.stderr.startswith('grasp-torque-sim: error: MuJoCo is not installed')
    assert len(done.stderr.splitlines()) == 1
