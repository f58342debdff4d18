# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The package in a scratch colcon workspace: ``colcon build`` and ``colcon test`` pass.

The workspace's src/ holds a copy of the repository (a copy, so that the build writes
nothing into the checkout); colcon (colcon-core, colcon-ros, colcon-python-setup-py,
colcon-package-selection, from the test extras) builds it with the compiled cycle, the
node it installed starts with ``cycle: compiled`` from the workspace, and ``colcon test``
runs the package's manifest and lint tests (a narrow selection: the whole suite would run
this test again inside itself; docs/ros2_control.md). Takes about 4 minutes, the C++
build's.
"""

import os
from pathlib import Path
import shutil
import signal
import subprocess
import sys
import time

from lint_files import ROOT
import pytest
from ros_domains import domain

COLCON = Path(sys.executable).with_name('colcon')
#: The tests ``colcon test`` runs in the workspace: the manifest and the ROS template's lints.
WORKSPACE_TESTS = ['test/test_package_manifest.py', 'test/test_xmllint.py',
                   'test/test_copyright.py']
#: Set in the inner ``colcon test``: a full ``colcon test`` does not build a workspace again.
INSIDE = 'GRASP_TORQUE_OPT_IN_WORKSPACE_TEST'

pytestmark = pytest.mark.skipif(bool(os.environ.get(INSIDE)),
                                reason="inside the workspace test's own colcon test")


def colcon(ws: Path, *args: str, timeout: float) -> subprocess.CompletedProcess:
    env = dict(os.environ, **{INSIDE: '1'})
    env.pop('PYTHONPATH', None)
    return subprocess.run([str(COLCON), *args], cwd=ws, env=env, capture_output=True,
                          text=True, timeout=timeout, stdin=subprocess.DEVNULL)


@pytest.fixture(scope='module')
def workspace(tmp_path_factory) -> Path:
    assert COLCON.is_file(), f'{COLCON} missing: pip install -e ".[test]" (scripts/setup.sh)'
    ws = tmp_path_factory.mktemp('colcon_ws')
    shutil.copytree(ROOT, ws / 'src' / 'grasp_torque_opt', ignore=shutil.ignore_patterns(
        '.venv', 'build', 'install', 'log', '.git', '*.so', '__pycache__', '*.egg-info',
        '.pytest_cache', '.hypothesis', '*.png', '*.jsonl'))
    started = time.monotonic()
    done = colcon(ws, 'build', '--packages-select', 'grasp_torque_opt', timeout=1200)
    print(f'colcon build: {time.monotonic() - started:.0f} s')
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-4000:]
    return ws


def test_colcon_build_installs_the_package_with_the_compiled_cycle(workspace):
    prefix = workspace / 'install' / 'grasp_torque_opt'
    executables = {p.name for p in (prefix / 'lib' / 'grasp_torque_opt').iterdir()}
    assert {'grasp_torque_node', 'grasp_torque_lifecycle_node', 'grasp-torque-opt',
            'grasp-torque-sim'} <= executables
    assert (prefix / 'share' / 'grasp_torque_opt' / 'package.xml').is_file()
    built = sorted(p.name.split('.')[0] for p in prefix.rglob('_fast_cycle*.so'))
    assert '_fast_cycle' in built, 'colcon build did not compile the cycle'


def test_the_workspace_node_starts_from_the_workspace_with_the_compiled_cycle(workspace):
    prefix = workspace / 'install' / 'grasp_torque_opt'
    params = prefix / 'share' / 'grasp_torque_opt' / 'config' / 'allegro_right_node.yaml'
    log = workspace / 'node.log'
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain('workspace')),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')
    env.pop('PYTHONPATH', None)
    script = ('. install/local_setup.sh && python -c "import grasp_torque_opt; '
              'print(\'from\', grasp_torque_opt.__file__)" && exec '
              f'{prefix}/lib/grasp_torque_opt/grasp_torque_node --ros-args --params-file '
              f'{params}')
    with log.open('wb') as out:
        node = subprocess.Popen(['bash', '-c', script], cwd=workspace, env=env, stdout=out,
                                stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    try:
        while 'cycle:' not in log.read_text() and node.poll() is None:
            assert time.monotonic() < deadline, log.read_text()[-3000:]
            time.sleep(0.2)
    finally:
        if node.poll() is None:
            node.send_signal(signal.SIGINT)
        code = node.wait(30)
    text = log.read_text()
    assert f'from {prefix}' in text, text[-3000:]
    assert 'cycle: compiled' in text, text[-3000:]
    assert code == 0, text[-3000:]


def test_colcon_test_passes(workspace):
    done = colcon(workspace, 'test', '--packages-select', 'grasp_torque_opt',
                  '--return-code-on-test-failure', '--pytest-args', *WORKSPACE_TESTS,
                  timeout=600)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-4000:]
    result = colcon(workspace, 'test-result', '--all', timeout=60)
    assert ' 0 errors, 0 failures' in result.stdout, result.stdout[-3000:]
    assert 'Summary: 0 tests' not in result.stdout, result.stdout
