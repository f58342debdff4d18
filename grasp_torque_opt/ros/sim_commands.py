# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
``grasp-torque-sim --driver``: the simulated hand behind one of the node's command interfaces.

The options of the driver models (:mod:`grasp_torque_opt.sim.drivers`), their checks,
the topic and message each takes (the node's, docs/node.md "Command interfaces"), a
message turned into the driver's command, and the node's parameters that match the
driver (``--with-node`` starts the node with them, over its params file).
"""

from __future__ import annotations

import argparse

from grasp_torque_opt.sim.drivers import DRIVERS, DriverSettings, node_overrides
import numpy as np


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the driver's options to grasp-torque-sim's parser."""
    d = p.add_argument_group(
        'driver', "the simulated hand's command interface; --with-node tells the node the "
        'same (command_interface and its constants)')
    d.add_argument('--driver', choices=DRIVERS, default='effort',
                   help='effort: torques plus the joint impedance --kp, --kd; position: a '
                        'position servo of stiffness --kp and damping --kd, limited in '
                        'current; current: a current-mode motor (k_t, gear, limit) plus the '
                        'impedance; hybrid: feed-forward torque with a PD of --kp, --kd')
    d.add_argument('--torque-constant', type=float, default=DriverSettings.torque_constant,
                   help="the motor's k_t [N m/A] (current; position's current limit)")
    d.add_argument('--gear-ratio', type=float, default=DriverSettings.gear_ratio,
                   help='joint torque over motor torque [-]')
    d.add_argument('--current-limit', type=float, default=DriverSettings.current_limit,
                   help="the driver's current limit [A] (current, position)")


def check(args: argparse.Namespace) -> str:
    """Check the driver's options; return the error ('' if none)."""
    for name in ('torque_constant', 'gear_ratio', 'current_limit'):
        value = getattr(args, name)
        if not (np.isfinite(value) and value > 0):
            return f"--{name.replace('_', '-')}: must be > 0"
    if args.driver in ('position', 'hybrid') and not args.kp > 0:
        return f'--kp: must be > 0 with --driver {args.driver} (its stiffness)'
    if args.driver != 'effort' and (args.controller != 'node' or args.plan is not None):
        return (f'--driver {args.driver}: only with the node over ROS (--controller node, '
                'no --plan)')
    return ''


def settings(args: argparse.Namespace) -> DriverSettings:
    """Return the driver the checked options ask for."""
    return DriverSettings(kind=args.driver, kp=args.kp, kd=args.kd,
                          torque_constant=args.torque_constant, gear_ratio=args.gear_ratio,
                          current_limit=args.current_limit)


def describe(s: DriverSettings) -> str:
    """Return the driver in words, for the run's first line."""
    if s.kind == 'effort':
        return f'effort driver, impedance Kp {s.kp:g} N m/rad Kd {s.kd:g} N m s/rad'
    if s.kind == 'position':
        return (f'position servo, stiffness K {s.kp:g} N m/rad, damping {s.kd:g} N m s/rad, '
                f'torque at the current limit {s.torque_limit:g} N m')
    if s.kind == 'current':
        return (f'current-mode motor, k_t {s.torque_constant:g} N m/A, gear '
                f'{s.gear_ratio:g}, limit {s.current_limit:g} A, impedance Kp {s.kp:g} '
                f'N m/rad Kd {s.kd:g} N m s/rad')
    return f'hybrid PD with feed-forward, kp {s.kp:g} N m/rad, kd {s.kd:g} N m s/rad'


def node_arguments(s: DriverSettings) -> list[str]:
    """Return the node's ``-p NAME:=VALUE`` arguments that match the driver."""
    out = []
    for name, value in node_overrides(s).items():
        text = f"[{', '.join(repr(float(v)) for v in value)}]" if isinstance(value, list) \
            else str(value)
        out += ['-p', f'{name}:={text}']
    return out


def subscription(kind: str) -> tuple[type, str]:
    """Return the message type and topic a driver takes (the node's interface's)."""
    from grasp_torque_opt.control.commands.registry import REGISTRY
    from sensor_msgs.msg import JointState
    from std_msgs.msg import Float64MultiArray

    entry = REGISTRY[kind]
    return (JointState if entry.message == 'joint_state' else Float64MultiArray), entry.topic


def command_of(msg, m: int) -> tuple[np.ndarray, ...] | None:
    """
    Give a command message's arrays (values; hybrid: effort, position, velocity).

    None when malformed: not m finite values in each.
    """
    if hasattr(msg, 'data'):
        arrays = (np.array(msg.data, dtype=float),)
    else:
        fields = (msg.effort, msg.position, msg.velocity)
        arrays = tuple(np.array(a, dtype=float) for a in fields)
    if any(a.shape != (m,) or not np.all(np.isfinite(a)) for a in arrays):
        return None
    return arrays
