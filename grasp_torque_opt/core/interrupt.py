# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
Ctrl-C while a console script starts: exit 130 without a traceback.

A console script (``grasp_torque_node``, ``grasp-torque-opt``, ...) imports the package
first and then, for a second or more, SciPy, Pinocchio and the rest, before its
``main()`` and its own KeyboardInterrupt handling run. An interrupt in that window
would end with Python's traceback; here it ends as a shell expects from Ctrl-C (exit
130, nothing printed). Only in those scripts: a program that imports the package keeps
its own handling.
"""

import os
import sys

#: The console scripts setup.py installs.
CONSOLE_SCRIPTS = frozenset({
    'grasp-torque-opt', 'grasp-torque-demo', 'grasp-torque-sim', 'grasp_torque_node',
    'grasp_torque_lifecycle_node', 'grasp_demo_driver', 'grasp_sim_driver'})


def quiet_interrupt_in_console_scripts() -> None:
    """In a console script, make an uncaught KeyboardInterrupt exit 130 quietly."""
    if os.path.basename(sys.argv[0] if sys.argv else '') not in CONSOLE_SCRIPTS:
        return
    previous = sys.excepthook

    def hook(kind, value, traceback) -> None:
        if issubclass(kind, KeyboardInterrupt):
            try:
                sys.stdout.flush()
            finally:
                os._exit(130)
        previous(kind, value, traceback)

    sys.excepthook = hook
