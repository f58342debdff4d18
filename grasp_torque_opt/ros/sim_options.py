# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
``grasp-torque-sim``'s options: the arguments, their checks, and the rig they ask for.

A test harness drives the simulated hand through these (docs/simulation.md,
"Disturbances"): the base's acceleration and shake, the object's true mass and
centre, encoder noise, the driver's gains, and which controller commands.
"""

from __future__ import annotations

import argparse

from grasp_torque_opt.core.command_line import add_version, HelpFormatter
from grasp_torque_opt.ros import sim_commands
import numpy as np

PROG = 'grasp-torque-sim'
CONTROLLERS = ('node', 'preset', 'impedance')
#: What joint_states' effort may be (grasp_torque_opt.sim.rig.EFFORT_REPORTS).
EFFORT_REPORTS = ('applied', 'commanded')
AXES = {'x': (1, 0, 0), 'y': (0, 1, 0), 'z': (0, 0, 1)}
#: The plot's baselines (grasp_torque_opt.ros.sim_compare.BASELINES; that module needs
#: MuJoCo, this one must not).
PLOT_BASELINES = ('loop-off', 'scenario')


def _disturbances(p: argparse.ArgumentParser) -> None:
    """Add the disturbances' group (what the controller is not told)."""
    g = p.add_argument_group('disturbances the controller is not told')
    g.add_argument('--base-accel', metavar='AX,AY,AZ', default=None,
                   help="the hand base's extra static acceleration from release on, base "
                        'axes [m/s^2] (simulated as apparent gravity)')
    g.add_argument('--base-shake', metavar='AMPLITUDE_G,FREQUENCY_HZ,AXIS', default=None,
                   help='sinusoidal base acceleration from release on: peak [g], frequency '
                        '[Hz], base axis x, y or z (e.g. 1,1,z)')
    g.add_argument('--mass-scale', type=float, default=1.0,
                   help="the simulated object's mass over the scenario's [-]")
    g.add_argument('--object-offset', metavar='DX,DY,DZ', default=None,
                   help="the simulated object's centre minus the scenario's, base axes [mm]")
    g.add_argument('--joint-noise', type=float, default=0.0,
                   help='encoder noise, standard deviation per 1 ms reading [mrad]: on the '
                        'published joint states and in the impedance')
    g.add_argument('--seed', type=int, default=0, help='seed of the encoder noise')
    g.add_argument('--effort-report', choices=EFFORT_REPORTS, default='applied',
                   help="what joint_states' effort is: applied, the torque the joints apply "
                        "(command plus impedance); commanded, the controller's last command "
                        "(as the Allegro V5's driver reports it; with --with-node the node is "
                        'told so, and the driver stiffness --kp)')


def parser(description: str) -> argparse.ArgumentParser:
    """Return the argument parser."""
    p = argparse.ArgumentParser(prog=PROG, formatter_class=HelpFormatter,
                                description=description, epilog=(
                                    'exit codes: 0 held, 1 not held (or no commands), 2 bad '
                                    'input. docs/simulation.md'))
    add_version(p)
    p.add_argument('--params', default='allegro_right_node.yaml',
                   help='node params file (bundled name or path); its scenario is simulated')
    p.add_argument('--duration', type=float, default=3.0,
                   help='seconds to hold after release [s]')
    p.add_argument('--settle', type=float, default=0.3,
                   help='seconds the commands press on the pinned object before release [s]')
    p.add_argument('--kp', type=float, default=1.0, help='joint impedance stiffness [N m/rad]')
    p.add_argument('--kd', type=float, default=0.01,
                   help='joint impedance damping [N m s/rad]')
    p.add_argument('--rate', type=float, default=250.0,
                   help='joint state (and IMU) rate [Hz]')
    p.add_argument('--contacts', action='store_true',
                   help="publish the contact frames measured in the simulation on 'contacts'")
    p.add_argument('--tactile', action='store_true',
                   help="publish the contact links' touch sensors on 'tactile' "
                        '(std_msgs/Float32MultiArray, one normal force [N] per scenario '
                        'contact, in their order; with --with-node the node reads them)')
    p.add_argument('--mu-tangential', type=float, default=None,
                   help="simulated tangential friction [-] (default: the scenario's)")
    p.add_argument('--mu-torsional', type=float, default=None,
                   help="simulated torsional friction [m] (default: the scenario's)")
    p.add_argument('--friction-scale', type=float, default=None,
                   help="simulated friction over the scenario's, tangential and torsional "
                        '[-] (not with --mu-tangential or --mu-torsional)')
    p.add_argument('--drift-limit', type=float, default=2.0,
                   help='the object counts as held while it moves less than this [mm]')
    p.add_argument('--rotation-limit', type=float, default=2.0,
                   help='... and turns less than this [deg]')
    p.add_argument('--lockstep', action='store_true',
                   help='advance the simulation only when the node has answered the latest '
                        'joint state (reproducible; slower than real time): docs/simulation.md')
    _disturbances(p)
    c = p.add_argument_group('controller')
    c.add_argument('--controller', choices=CONTROLLERS, default='node',
                   help='node: grasp_torque_node over ROS; preset: fixed closing torques of '
                        'one level, tuned on the nominal load; impedance: the grasp pose '
                        'commanded inside the object (position control)')
    c.add_argument('--preset-level', type=float, default=None,
                   help='preset: the normal force level [N] (default: tuned at start)')
    c.add_argument('--squeeze-depth', type=float, default=5.0,
                   help='impedance: how far inside the object the contacts are commanded '
                        '[mm]')
    sim_commands.add_arguments(p)
    p.add_argument('--picture', default='grasp_sim.png',
                   help='PNG of the grasp written at the end, in the current folder unless a '
                        'path')
    p.add_argument('--plot', default='grasp_sim_plot.png',
                   help="PNG of the object's drift and the hand's effort over time, this "
                        'run beside a baseline (--plot-baseline) on the same disturbances, '
                        'simulated without ROS; in the current folder unless a path')
    p.add_argument('--plot-baseline', choices=PLOT_BASELINES, default='loop-off',
                   help="the plot's baseline: loop-off, the node on the same params file "
                        'with the object loop off (object_loop.enabled false: feedforward '
                        'only); scenario, the node told only the scenario (no IMU, no '
                        'efforts, friction margin 0)')
    p.add_argument('--no-picture', action='store_true', help='write no picture and no plot')
    p.add_argument('--with-node', action='store_true',
                   help='start grasp_torque_node in a child process')
    p.add_argument('--wait', type=float, default=30.0,
                   help='how long to wait for the node and its first command [s]')
    loop = p.add_argument_group(
        "the planner's loop", 'simulate the best-ranked feasible candidate of a plan with '
        "the node's own cycle, in simulated time without ROS (docs/planner.md)")
    loop.add_argument('--plan', metavar='PLAN',
                      help="candidate lines of 'grasp-torque-opt plan' (merged into the "
                           "--params file's scenario)")
    loop.add_argument('--scores', metavar='SCORES',
                      help="their records from 'grasp-torque-opt score --out' (the rank)")
    return p


def _triple(text: str) -> np.ndarray | None:
    try:
        values = np.array([float(v) for v in text.split(',')])
    except ValueError:
        return None
    return values if values.shape == (3,) and np.all(np.isfinite(values)) else None


def _shake(text: str) -> tuple[float, float, np.ndarray] | None:
    parts = text.split(',')
    if len(parts) != 3 or parts[2].strip().lower() not in AXES:
        return None
    try:
        amplitude, frequency = float(parts[0]), float(parts[1])
    except ValueError:
        return None
    if not (np.isfinite(amplitude) and np.isfinite(frequency) and amplitude >= 0
            and frequency > 0):
        return None
    return amplitude, frequency, np.array(AXES[parts[2].strip().lower()], dtype=float)


def check(args: argparse.Namespace) -> str:
    """
    Check the arguments and parse the compound ones in place; return the error ('' if none).

    Sets ``args.base_accel`` (m/s^2, shape (3,)), ``args.base_shake`` (amplitude [g],
    frequency [Hz], unit axis, or None) and ``args.object_offset`` (m, shape (3,)).
    """
    for name in ('duration', 'rate', 'wait', 'drift_limit', 'rotation_limit', 'mass_scale'):
        if not getattr(args, name) > 0:
            return f"--{name.replace('_', '-')}: must be > 0"
    for name in ('settle', 'kp', 'kd', 'joint_noise', 'squeeze_depth'):
        if not getattr(args, name) >= 0:
            return f"--{name.replace('_', '-')}: must be >= 0"
    for name in ('mu_tangential', 'mu_torsional', 'preset_level', 'friction_scale'):
        value = getattr(args, name)
        if value is not None and not value > 0:
            return f"--{name.replace('_', '-')}: must be > 0"
    if args.friction_scale is not None and not np.isfinite(args.friction_scale):
        return '--friction-scale: must be finite'
    if args.friction_scale is not None and (args.mu_tangential is not None
                                            or args.mu_torsional is not None):
        return ('--friction-scale: not with --mu-tangential or --mu-torsional (give the '
                'scale of both, or the values)')
    if args.lockstep and args.controller != 'node':
        return f'--lockstep: only with --controller node (got {args.controller})'
    if args.lockstep and getattr(args, 'driver', 'effort') != 'effort':
        return ('--lockstep: only with --driver effort (it applies the stamped torques), '
                f'got {args.driver}')
    for name in ('base_accel', 'object_offset'):
        text = getattr(args, name)
        value = np.zeros(3) if text is None else _triple(text)
        if value is None:
            return f"--{name.replace('_', '-')}: three numbers separated by commas, got {text!r}"
        setattr(args, name, value)
    args.object_offset = args.object_offset * 1e-3
    if args.base_shake is not None:
        shake = _shake(args.base_shake)
        if shake is None:
            return ('--base-shake: AMPLITUDE_G,FREQUENCY_HZ,AXIS with amplitude >= 0, '
                    f'frequency > 0 and axis x, y or z, got {args.base_shake!r}')
        args.base_shake = shake
    if args.effort_report == 'commanded' and not args.kp > 0:
        return ('--effort-report commanded: needs --kp > 0 (the command alone says nothing '
                'of the load; the position error times Kp does)')
    if args.with_node and args.controller != 'node':
        return f'--with-node: only with --controller node (got {args.controller})'
    driver = sim_commands.check(args)
    if driver:
        return driver
    if (args.plan is None) != (args.scores is None):
        return '--plan and --scores: give both (the plan and its scores) or neither'
    if args.plan is not None and (args.with_node or args.controller != 'node'):
        return ("--plan: the node's own cycle simulates the candidate, without ROS: not "
                'with --with-node or --controller ' + args.controller)
    return ''


def friction(args: argparse.Namespace, scenario) -> tuple[float | None, float | None]:
    """Return the simulated (tangential, torsional) friction: the options, or the scaled."""
    if args.friction_scale is None:
        return args.mu_tangential, args.mu_torsional
    return (args.friction_scale * scenario.friction.mu1,
            args.friction_scale * scenario.friction.mu2)


def rig_settings(args: argparse.Namespace):
    """Return the episode settings (disturbances, mass, offset, gains) the checked args ask."""
    from grasp_torque_opt.sim.base_motion import BaseMotion, STANDARD_GRAVITY
    from grasp_torque_opt.sim.episode import EpisodeSettings
    from grasp_torque_opt.sim.rig import Disturbances

    motion = BaseMotion(accel=args.base_accel)
    if args.base_shake is not None:
        amplitude, frequency, axis = args.base_shake
        motion = BaseMotion(accel=args.base_accel, shake_amplitude=amplitude * STANDARD_GRAVITY,
                            shake_frequency=frequency, shake_axis=axis)
    return EpisodeSettings(
        kp=args.kp, kd=args.kd, duration=args.duration, settle=args.settle, rate=args.rate,
        drift_limit=args.drift_limit * 1e-3,
        disturbances=Disturbances(motion=motion, joint_noise=args.joint_noise * 1e-3,
                                  seed=args.seed),
        mass_scale=args.mass_scale, object_offset=tuple(args.object_offset),
        effort_report=args.effort_report)


def describe(args: argparse.Namespace) -> str:
    """Return the disturbances asked for, in words ('' for none)."""
    parts = []
    if np.any(args.base_accel):
        parts.append('base acceleration [' + ', '.join(f'{v:g}' for v in args.base_accel)
                     + '] m/s^2')
    if args.base_shake is not None:
        amplitude, frequency, axis = args.base_shake
        name = next(k for k, v in AXES.items() if np.allclose(v, axis))
        parts.append(f'base shake {amplitude:g} g at {frequency:g} Hz along {name}')
    if args.mass_scale != 1.0:
        parts.append(f'mass x{args.mass_scale:g}')
    if np.any(args.object_offset):
        parts.append('object offset [' + ', '.join(f'{1e3 * v:g}' for v in args.object_offset)
                     + '] mm')
    if args.friction_scale is not None and args.friction_scale != 1.0:
        parts.append(f'friction x{args.friction_scale:g}')
    if args.joint_noise > 0:
        parts.append(f'joint noise {args.joint_noise:g} mrad')
    if args.effort_report != 'applied':
        parts.append(f'efforts reported: {args.effort_report}')
    return ', '.join(parts)
