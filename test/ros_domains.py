# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The ROS domains of one test run: ROS_DOMAIN_ID + 1 to ROS_DOMAIN_ID + SPAN, one per role.

A run under ``ROS_DOMAIN_ID=B`` uses the domains B+1 to B+SPAN and no other: B itself
(the shell's own domain, perhaps a robot's) is left alone, and every role below has a
domain of its own, so no two kinds of process of one run share one by accident. Two
runs on one machine (or a run beside a robot) stay apart when their bases are at least
SPAN apart. Without ROS_DOMAIN_ID the base is a multiple of SPAN from the process id,
so two runs usually differ. The base and the span are the package's rule
(grasp_torque_opt.ros.domains, which the benchmarks and ``--with-node`` use too); the
roles are the suite's. Every process also discovers on localhost only. Plain module,
no rclpy: the subprocess scripts use it too.
"""

from grasp_torque_opt.ros.domains import base, SPAN

#: Each role's offset above the base.
ROLES = {
    'in_process': 1,          # ros_harness.Harness: nodes inside the pytest process
    'process': 2,             # ros_harness.NodeProcess and the simulated hand's processes
    'doc_commands': 3,        # test_doc_commands.py: the documented commands
    'sim_listen': 4,          # test_sim_driver.py's listener, attempts 0 to 2: 4, 5, 6
    'without_mujoco': 7,      # test_without_mujoco.py's script
    'without_optional': 8,    # test_without_optional_solvers.py's script
    'workspace': 9,           # test_colcon_workspace.py: the node the workspace built
    'sim_commanded': 10,      # test_sim_driver.py's commanded-effort listener: 10, 11, 12
}

#: The roles with three domains, one per attempt.
ATTEMPTS = ('sim_listen', 'sim_commanded')


BASE = base()


def domain(role: str, attempt: int = 0) -> int:
    """Return the domain of ``role`` in this run (``attempt`` for a role with several)."""
    if attempt and role not in ATTEMPTS:
        raise ValueError(f'{role} has one domain')
    if not 0 <= attempt < 3:
        raise ValueError(f'{role} has 3 domains')
    return BASE + ROLES[role] + attempt


def run_domains() -> range:
    """Return every domain this run may use."""
    return range(BASE + 1, BASE + SPAN + 1)
