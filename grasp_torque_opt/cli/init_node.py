# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
``grasp-torque-opt init-node SCENARIO --out FILE``: the node's params file for any scenario.

A hand of one's own used to start from a copy of the Allegro's params file, and kept
the Allegro's sixteen torque limits, IMU and uncertainty settings: the node refused it
("torque_limits: must have 6 entries, got 16"). This writes a file from the scenario
alone: the scenario's path, gravity compensation where the scenario states gravity, the
hand's torque limits (the scenario's, else the URDF's effort limits: what the node
would take by default, written out so that one sees them), the timeouts and the fault
policy at the schema's defaults, and every input that needs a sensor (IMU, efforts,
contacts topic) off, each with a comment that says how to turn it on. Beside it, a
ros2_control controllers file whose effort controller lists the hand's actuated
joints in the node's command order.

The file is written as text, not dumped, so that its comments survive (PyYAML drops
comments); the test reads it back with the node's own schema and starts the node on it.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from grasp_torque_opt.cli.args import EPILOG, SCENARIO_HELP
from grasp_torque_opt.control.parameters.schema import Schema
from grasp_torque_opt.core.command_line import EXIT_OK, HelpFormatter
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.resources import config_dirs, find_config, package_version
from grasp_torque_opt.core.scenario import load_scenario
import numpy as np

#: The settings written at the schema's default, in this order.
TIMING = ('joint_state_timeout', 'contacts_timeout', 'wrench_timeout', 'hold_time',
          'fault_policy')


def add_parser(sub) -> None:
    """Add ``init-node`` to the CLI's subparsers."""
    p = sub.add_parser('init-node', help="write the node's params file for a scenario",
                       formatter_class=HelpFormatter, epilog=EPILOG, description=(
                           "Write grasp_torque_node's params file for a scenario (its "
                           'joints and torque limits, nothing of another hand) and a '
                           'ros2_control controllers file beside it (docs/your-hand.md).'))
    p.add_argument('scenario', help=SCENARIO_HELP)
    p.add_argument('--out', required=True, metavar='FILE',
                   help='the params file to write (e.g. my_hand_node.yaml)')
    p.add_argument('--controllers', metavar='FILE', default=None,
                   help='the controllers file to write (default: FILE with _controllers '
                        'instead of _node, or _controllers added)')
    p.add_argument('--force', action='store_true', help='overwrite files that exist')


def scenario_reference(name: str, cwd: Path | None = None) -> str:
    """
    Return how the params file names the scenario: as the node will find it.

    The node takes a relative path from the folder it starts in, else as a bundled name:
    a bundled name stays a name, a file under the current folder stays relative to it,
    any other file is written as an absolute path.
    """
    cwd = Path.cwd() if cwd is None else cwd
    path = Path(name).expanduser()
    if not os.path.exists(path):
        return name  # found among the bundled files (find_config checked it exists)
    full = path.resolve()
    bundled = [d.resolve() for d in config_dirs()]
    if full.parent in bundled and not path.is_absolute() and path.parent == Path('.'):
        return name
    try:
        return str(full.relative_to(cwd.resolve()))
    except ValueError:
        return str(full)


def controllers_path(out: Path) -> Path:
    """Return the default controllers file beside ``out``."""
    stem = out.stem
    stem = stem[:-5] if stem.endswith('_node') else stem
    return out.with_name(f'{stem}_controllers{out.suffix or ".yaml"}')


def _double(value: float) -> str:
    """Return a double as ROS's params parser reads it: with a point (6 is an integer)."""
    text = f'{float(value):.6g}'
    return text if any(c in text for c in '.en') else text + '.0'


def _flow(values) -> str:
    return '[' + ', '.join(values) + ']'


def _wrapped(key: str, items: list[str], indent: int, comment: bool = False) -> str:
    """``key: [a, b, ...]`` wrapped at 99 columns, continuation lines under the first item."""
    head = ' ' * indent + ('# ' if comment else '')
    lines, line = [], head + f'{key}: ['
    pad = ' ' * len(line)
    if comment:
        pad = head + ' ' * (len(line) - len(head))
    for i, item in enumerate(items):
        text = item + (', ' if i < len(items) - 1 else ']')
        if len(line) + len(text.rstrip()) > 99 and not line.endswith('['):
            lines.append(line.rstrip())
            line = pad
        line += text
    lines.append(line)
    return '\n'.join(lines)


def params_text(scenario_name: str, setup: GraspSetup, gravity: np.ndarray | None,
                source: str) -> str:
    """Return the params file's text for a bound scenario."""
    defaults = Schema.load().defaults()
    hand = setup.hand
    limits = [_double(v) for v in hand.torque_limits]
    lines = [
        f'# grasp_torque_node for {source}: {hand.m} actuated joints.',
        f'# Written by grasp-torque-opt init-node ({package_version()}) from the scenario '
        'alone;',
        '# every parameter is in docs/node.md, "Parameters". Start the node with',
        '#   ros2 run grasp_torque_opt grasp_torque_node --ros-args --params-file <this file>',
        '/**:  # any node name and namespace',
        '  ros__parameters:',
        f'    scenario: {scenario_name}  # a relative path is taken from the folder the '
        'node starts in',
    ]
    if gravity is not None:
        g = _flow(f'{float(v):g}' for v in gravity)
        lines += [f"    # the scenario's gravity {g} m/s^2 (base axes) gives g(q) and the load",
                  '    gravity_compensation: true']
    else:
        lines += ['    # the scenario states no gravity: set gravity (m/s^2, base axes) and',
                  "    # turn this on for the fingers' own weight",
                  '    gravity_compensation: false']
    lines += ["    # |command_i| <= limit_i [N m], the scenario's hand.torque_limits, else the "
              "URDF's",
              '    # effort limits, in the order of the joints below: lower them, never raise',
              "    # them above the motors' rating",
              _wrapped('joints', list(hand.joints), 4, comment=True),
              _wrapped('torque_limits', limits, 4)]
    for name in TIMING:
        value = defaults[name]
        lines.append(f'    {name}: {value}')
    lines += [
        '    # Inputs that need a sensor, off until the hand has one (docs/node.md):',
        '    # a palm IMU on the imu topic (sensor_msgs/Imu): the apparent gravity and the',
        "    # base's motion go into g(q) and the load",
        '    imu:',
        '      enabled: false',
        "    # the load from joint_states' effort: only with a driver whose effort is a",
        '    # torque (docs/node.md, "Load from efforts")',
        '    effort_estimation:',
        '      enabled: false',
        '    # stated uncertainty -> a friction margin (docs/node.md, "Margin"), e.g.',
        '    # uncertainty: {friction: 0.1, pose: 0.003}',
    ]
    return '\n'.join(lines) + '\n'


def controllers_text(setup: GraspSetup, source: str) -> str:
    """Return the ros2_control controllers file's text: one effort controller, the joints."""
    joints = list(setup.hand.joints)
    return '\n'.join([
        f'# ros2_control controllers for grasp_torque_node on {source}, written by',
        "# grasp-torque-opt init-node. The effort controller's joints are the node's",
        "# joints in the same order: the node's command i is joint i of this list. Each",
        "# joint's hardware interface must export an `effort` command interface",
        '# (docs/ros2_control.md).',
        'controller_manager:',
        '  ros__parameters:',
        '    update_rate: 1000  # Hz',
        '    joint_state_broadcaster:',
        '      type: joint_state_broadcaster/JointStateBroadcaster',
        '    effort_controller:',
        '      type: effort_controllers/JointGroupEffortController',
        '',
        'effort_controller:',
        '  ros__parameters:',
        _wrapped('joints', joints, 4),
    ]) + '\n'


def run(args: argparse.Namespace) -> int:
    """Write the params file and the controllers file; print where."""
    path = find_config(args.scenario)
    scenario = load_scenario(path)
    setup = GraspSetup.from_scenario(scenario)
    out = Path(args.out)
    controllers = Path(args.controllers) if args.controllers else controllers_path(out)
    if out.resolve() == controllers.resolve():
        raise InputError('--controllers', f'the same file as --out: {out}')
    for field, target in (('--out', out), ('--controllers', controllers)):
        if target.exists() and not args.force:
            raise InputError(field, f'{target} exists (--force overwrites it)')
        if not target.parent.is_dir():
            raise InputError(field, f'no such folder: {target.parent}')
    gravity = None if scenario.gravity is None else np.asarray(scenario.gravity, dtype=float)
    source = Path(scenario.source).name
    out.write_text(params_text(scenario_reference(args.scenario), setup, gravity, source))
    controllers.write_text(controllers_text(setup, source))
    print(f'params: {out} ({setup.hand.m} joints, torque limits '
          f'{min(setup.hand.torque_limits):g} to {max(setup.hand.torque_limits):g} N m)')
    print(f'controllers: {controllers}')
    return EXIT_OK
