# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The nodes' ``-h``: what they do, the ``--ros-args`` they take, their topics.

A node's own options are few (``--executor``); what a user needs is in the ROS
arguments: the required ``scenario`` parameter, a params file, remaps. This module
holds that text and the parser that shows it, without importing rclpy, so that the
node's ``run()`` builds its parser here (docs/node.md).
"""

from __future__ import annotations

import argparse
import textwrap

from grasp_torque_opt.core.command_line import add_version, HelpFormatter

#: The managed node's executable.
MANAGED = 'grasp_torque_lifecycle_node'

#: Topics and services, one line each: (direction, name, type, what).
TOPICS = (
    ('sub', 'joint_states', 'sensor_msgs/JointState', 'joint positions; each runs one cycle'),
    ('sub', 'contacts', 'geometry_msgs/PoseArray', "contact frames (default: the scenario's)"),
    ('sub', 'external_wrench', 'geometry_msgs/WrenchStamped',
     "load on the object (default: the scenario's)"),
    ('sub', 'gravity', 'geometry_msgs/Vector3Stamped',
     "gravity in the base frame (default: the scenario's)"),
    ('pub', 'effort_commands', 'std_msgs/Float64MultiArray',
     'certified joint torques in `joints` order, for a JointGroupEffortController'),
    ('pub', '~/contact_wrenches', 'visualization_msgs/MarkerArray', 'contact force arrows'),
    ('pub', '/diagnostics', 'diagnostic_msgs/DiagnosticArray', 'status, times, faults (1 Hz)'),
    ('srv', '~/solve', 'std_srvs/Trigger', 'solve once, answer the JSON of solve --json'),
)


def description(prog: str) -> str:
    """Return what the node does, in a few lines."""
    managed = prog == MANAGED
    what = ('the managed (lifecycle) node: configure loads the hand, activate starts the '
            'commands' if managed else 'it commands from its start')
    return textwrap.fill(
        f'{prog}: minimum-effort joint torques for the grasp of a dexterous hand, solved '
        'and certified on each joint state and published as effort commands for a '
        f'ros2_control effort controller ({what}).', 79)


def epilog(prog: str) -> str:
    """Return the ROS arguments, the topics (one line each) and where the rest is."""
    width = max(len(name) for _, name, _, _ in TOPICS)
    topics = '\n'.join(f'  {d} {name:<{width}}  {kind}: {what}'
                       for d, name, kind, what in TOPICS)
    return (
        'ROS arguments (after --ros-args):\n'
        '  -p scenario:=FILE          required: the scenario file (a path, or a bundled\n'
        '                             name: allegro_right.yaml, planar_two_finger.yaml)\n'
        '  --params-file FILE         parameters from a YAML file, e.g.\n'
        '                             config/allegro_right_node.yaml (sets scenario)\n'
        '  -p NAME:=VALUE             any parameter (docs/node.md, Parameters)\n'
        '  -r effort_commands:=TOPIC  remap a topic, e.g. to /effort_controller/commands\n'
        '  -r __node:=NAME, -r __ns:=NS  another node name or namespace\n'
        f'topics and services (relative names, remappable):\n{topics}\n'
        'example:\n'
        f'  {prog} --ros-args --params-file config/allegro_right_node.yaml \\\n'
        '      -r effort_commands:=/effort_controller/commands\n'
        + textwrap.fill('exit codes: 0 stopped (SIGINT, SIGTERM), 2 refused to run (one line '
                        'on stderr: a bad parameter, scenario or ROS argument). Topics, '
                        'parameters and faults: docs/node.md', 79))


class _Formatter(HelpFormatter, argparse.RawDescriptionHelpFormatter):
    """Defaults in the options' help; the epilog's lines kept as written."""


def node_parser(prog: str) -> argparse.ArgumentParser:
    """
    Return the node's parser: description, ``--ros-args`` epilog and ``--version``.

    ``run()`` adds the node's own options (``--executor``) and parses what
    ``rclpy.utilities.remove_ros_args`` leaves.
    """
    parser = argparse.ArgumentParser(prog=prog, formatter_class=_Formatter,
                                     description=description(prog), epilog=epilog(prog))
    add_version(parser)
    return parser
