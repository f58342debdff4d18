# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The node runs with a ROS distribution's packages alone.

No Clarabel, DAQP, quadprog, threadpoolctl, OSQP or MuJoCo (pip installs them; rosdep
may not have them).
"""

import subprocess
import sys

from conftest import ALLEGRO, ROOT
from ros_domains import domain

TEST_DIR = ROOT / 'test'  # for cycle_inputs

OPTIONAL = ('clarabel', 'daqp', 'quadprog', 'threadpoolctl', 'osqp', 'mujoco')

SCRIPT = f"""
import sys, time, warnings
for name in {OPTIONAL!r}:
    sys.modules[name] = None          # any import of these now raises ImportError
import rclpy
from rclpy.parameter import Parameter
from grasp_torque_opt.backends import single_threaded_math
from grasp_torque_opt.ros.node import GraspTorqueNode
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from cycle_inputs import joint_state
from grasp_torque_opt import GraspSetup
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    single_threaded_math()
assert any("threadpoolctl is not installed" in str(w.message) for w in caught), caught
rclpy.init(domain_id={domain('without_optional')})
node = GraspTorqueNode(parameter_overrides=[Parameter("scenario", value={str(ALLEGRO)!r}),
                                            Parameter("cycle_budget", value=1.0)])
assert node.controller.fallback is None, "DAQP absent: no fallback, not a crash"
refused = node.set_parameters([Parameter("solver.backend", value="daqp")])[0]
assert not refused.successful and "daqp is not installed" in refused.reason, refused.reason
setup = GraspSetup.from_file({str(ALLEGRO)!r})
names, positions = joint_state(setup)
now = time.monotonic()
node.controller.take("joint_states", JointStateReading(names, positions), now)
result = node.controller.cycle(now)
assert result.kind == "solution" and result.solution.optimal, result
assert result.solution.backend == "proxsuite"
print("ok")
"""


def test_the_node_solves_with_the_optional_solvers_absent():
    done = subprocess.run([sys.executable, '-c', SCRIPT], capture_output=True, text=True,
                          timeout=120, cwd=TEST_DIR)
    assert done.returncode == 0, done.stderr[-3000:]
    assert 'solver.fallback: daqp is not installed' in done.stderr
