"""The numerical core imports, and solves, with ROS absent."""

import subprocess
import sys

from conftest import PLANAR

SCRIPT = f"""
import pkgutil, sys
for name in ("rclpy", "std_msgs", "sensor_msgs", "geometry_msgs", "std_srvs"):
    sys.modules[name] = None          # any import of these now raises ImportError
import grasp_torque_opt
core = [m.name for m in pkgutil.iter_modules(grasp_torque_opt.__path__)
        if m.name not in ("node", "demo_driver")]
for name in core:
    __import__("grasp_torque_opt." + name)
from grasp_torque_opt.grasp_setup import GraspSetup
from grasp_torque_opt.solve import solve
assert solve(GraspSetup.from_file({str(PLANAR)!r})).status == "optimal"
print(len(core))
"""


def test_core_imports_without_rclpy():
    done = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert int(done.stdout) >= 10
