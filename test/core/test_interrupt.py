# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""Ctrl-C while a console script starts: exit 130, no traceback (core/interrupt.py)."""

import os
from pathlib import Path
import signal
import subprocess
import sys

from conftest import ROOT
import pytest

#: What a console script does before its main(): import the package, then the slow rest.
SLOW_START = """import sys, time
import grasp_torque_opt
print('ready', flush=True)
time.sleep(60)
"""


def interrupted(path: Path) -> subprocess.CompletedProcess:
    path.write_text(f'#!{sys.executable}\n{SLOW_START}')
    path.chmod(0o755)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    p = subprocess.Popen([str(path)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True, env=env)
    assert p.stdout.readline() == 'ready\n'
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=30)
    return subprocess.CompletedProcess(p.args, p.returncode, out, err)


@pytest.mark.parametrize('script', ['grasp_torque_node', 'grasp-torque-opt', 'grasp-torque-sim'])
def test_ctrl_c_during_a_console_scripts_start_exits_130_quietly(tmp_path, script):
    done = interrupted(tmp_path / script)
    assert done.returncode == 130 and done.stderr == '', done.stderr


def test_another_program_keeps_pythons_own_interrupt(tmp_path):
    done = interrupted(tmp_path / 'my_planner')
    assert done.returncode == -signal.SIGINT and 'KeyboardInterrupt' in done.stderr
