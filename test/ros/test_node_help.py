# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The nodes' -h: what they do, the --ros-args they take, their topics one line each."""

from importlib import metadata
from pathlib import Path
import subprocess
import sys

from grasp_torque_opt.ros.node_help import node_parser, TOPICS
import pytest

NODES = ['grasp_torque_node', 'grasp_torque_lifecycle_node']


@pytest.mark.parametrize('prog', NODES)
def test_the_help_says_the_ros_arguments_and_the_topics(prog):
    text = node_parser(prog).format_help()
    assert f'{prog}: minimum-effort joint torques' in text
    assert 'scenario:=FILE' in text and 'required' in text
    assert '--params-file FILE' in text and 'effort_commands:=' in text
    lines = text.splitlines()
    for _, name, kind, _ in TOPICS:  # each topic on one line, with its type
        assert any(name in line and kind in line for line in lines), name
    assert ('lifecycle' in text) == (prog == 'grasp_torque_lifecycle_node')


def test_the_parser_takes_what_remove_ros_args_leaves():
    parser = node_parser('grasp_torque_node')
    parser.add_argument('--executor', default='single')
    assert parser.parse_args(['--executor', 'events']).executor == 'events'
    with pytest.raises(SystemExit):
        parser.parse_args(['--version'])


@pytest.mark.parametrize('prog', NODES)
def test_the_executables_show_it(prog):
    exe = str(Path(sys.executable).parent / prog)
    done = subprocess.run([exe, '-h'], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0
    assert 'scenario:=FILE' in done.stdout and 'joint_states' in done.stdout
    done = subprocess.run([exe, '--version'], capture_output=True, text=True, timeout=60)
    assert done.stdout.split()[:2] == [prog, metadata.version('grasp_torque_opt')]
