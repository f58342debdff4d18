# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The numerical core imports, and solves, with ROS absent; the core alone needs no solver."""

import subprocess
import sys

from conftest import PLANAR

ROS = ('rclpy', 'std_msgs', 'sensor_msgs', 'geometry_msgs', 'std_srvs', 'visualization_msgs',
       'diagnostic_msgs', 'rcl_interfaces')
SOLVERS = ('proxsuite', 'daqp', 'quadprog', 'clarabel', 'osqp', 'scipy.optimize', 'mujoco')


def run(script: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-c', script], capture_output=True, text=True,
                          timeout=120)


def blocked(names) -> str:
    """Python lines after which importing any of ``names`` raises ImportError."""
    return ''.join(f'sys.modules[{n!r}] = None\n' for n in names)


def test_everything_but_the_ros_family_imports_and_solves_without_ros():
    done = run('import pkgutil, sys\n' + blocked(ROS) + f"""
import grasp_torque_opt
names = [m.name for m in pkgutil.walk_packages(grasp_torque_opt.__path__, "grasp_torque_opt.")
         if not m.name.startswith("grasp_torque_opt.ros")]
for name in names:
    __import__(name)
from grasp_torque_opt import GraspSetup, solve
assert solve(GraspSetup.from_file({str(PLANAR)!r})).status == "optimal"
print(len(names))
""")
    assert done.returncode == 0, done.stderr
    assert int(done.stdout) >= 20


def test_the_core_imports_and_builds_with_every_solver_and_ros_blocked():
    done = run('import pkgutil, sys\n' + blocked(ROS + SOLVERS) + f"""
import grasp_torque_opt.core as core
names = [m.name for m in pkgutil.walk_packages(core.__path__, "grasp_torque_opt.core.")]
for name in names:
    __import__(name)
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.tau_qp import build_tau_qp
setup = GraspSetup.from_file({str(PLANAR)!r})
qp = build_tau_qp(setup.maps(), setup.friction, setup.external_wrench, *setup.tau_bounds,
                  setup.weights)
print(len(names), qp.H.shape[0])
""")
    assert done.returncode == 0, done.stderr
    modules, n = map(int, done.stdout.split())
    assert modules >= 10 and n >= 4
