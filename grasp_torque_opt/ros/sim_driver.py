# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
A simulated hand driver: the scenario's hand and object in MuJoCo, on the node's topics.

What a real hand with a ros2_control effort controller would be (docs/simulation.md):
MuJoCo steps in real time at 1 kHz; ``joint_states`` carries positions,
velocities and the efforts applied (``--effort-report commanded``: the last command
received, as the Allegro V5's driver reports it); the latest ``effort_commands`` is applied
as joint torques and held until the next one (no timeout, as the effort
controller does), plus a joint impedance Kp, Kd around the configuration the
fingers settled in, as real hand drivers add. Until the first command the
fingers hold their grasp configuration and the object is pinned; the commands
then press the fingers on it for ``--settle`` seconds before it is released.

Each second it prints the object's drift [mm] and rotation [deg], the contact
forces measured against the node's predicted contact wrenches (from its
``~/solve`` service) and the friction usage; at the end, held or not and why, and
one rendered picture of the grasp. ``--with-node`` starts ``grasp_torque_node`` in a
child process first, on a private ROS domain with localhost-only discovery.
Exit code: 0 held, 1 not held (or no commands), 2 bad input.
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
import sys
import time

from grasp_torque_opt.core.command_line import EXIT_INTERRUPTED
from grasp_torque_opt.ros.node_process import isolate, node_process, scenario_of
from grasp_torque_opt.ros.sim_options import check, describe, parser, PROG, rig_settings
import numpy as np


def _description() -> str:
    """Return the module's docstring up to its exit codes: what the script does."""
    return __doc__.split('Exit code:')[0].strip()


def main(argv: list[str] | None = None) -> int:
    """Run the simulated hand; exit code 0 when the object stayed held."""
    args = parser(_description()).parse_args(argv)
    reason = check(args)
    if reason:
        print(f'{PROG}: error: {reason}', file=sys.stderr)
        return 2
    # Offscreen rendering through EGL: MuJoCo reads this when it is first imported.
    os.environ.setdefault('MUJOCO_GL', 'egl')
    try:
        import mujoco  # noqa: F401 -- only whether MuJoCo is installed
    except ImportError:
        print(f"{PROG}: error: MuJoCo is not installed (the 'sim' extra: "
              "pip install -e '.[sim]', or bash scripts/setup.sh)", file=sys.stderr)
        return 2
    from grasp_torque_opt.core.exceptions import InputError
    from grasp_torque_opt.core.resources import find_config
    from grasp_torque_opt.core.scenario import load_scenario
    from grasp_torque_opt.sim.episode import simulated
    from grasp_torque_opt.sim.model import SimSettings

    if args.plan is not None:
        return _simulate_best(args)
    if args.with_node:
        isolate()
    try:
        params = find_config(args.params, '--params')
        scenario = load_scenario(find_config(scenario_of(params)))
        setup, rig = simulated(scenario, rig_settings(args), sim=SimSettings(
            mu_tangential=args.mu_tangential, mu_torsional=args.mu_torsional))
        baseline = _baseline(args, scenario, setup)
    except (InputError, ValueError) as e:
        print(f'{PROG}: error: {e}', file=sys.stderr)
        return 2
    try:
        told = () if args.effort_report == 'applied' else (  # the node told what they are
            'effort_estimation.driver_stiffness:=' + repr(float(args.kp)),
            'effort_estimation.effort_report:=commanded')
        with node_process(params, args.with_node, told):
            return _run(args, scenario, setup, rig, baseline)
    except KeyboardInterrupt:
        print(f'{PROG}: interrupted', file=sys.stderr)
        return EXIT_INTERRUPTED


def _simulate_best(args: argparse.Namespace) -> int:
    """Simulate the best candidate of --plan by --scores: the planner's loop's last step."""
    from grasp_torque_opt.core.exceptions import InputError
    from grasp_torque_opt.core.resources import find_config
    from grasp_torque_opt.ros.sim_plan import run
    from grasp_torque_opt.sim.model import SimSettings

    try:
        base = find_config(scenario_of(find_config(args.params, '--params')))
        return run(args, base, rig_settings(args), SimSettings(
            mu_tangential=args.mu_tangential, mu_torsional=args.mu_torsional))
    except (InputError, ValueError) as e:
        print(f'{PROG}: error: {e}', file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f'{PROG}: interrupted', file=sys.stderr)
        return EXIT_INTERRUPTED


def _baseline(args: argparse.Namespace, scenario, setup):
    """Return the baseline controller asked for (None: the node), and say how it is set."""
    from grasp_torque_opt.sim.baselines import Preset, Squeeze, tune_preset

    if args.controller == 'preset':
        level = args.preset_level
        if level is None:
            tuned = tune_preset(scenario, args.kp, args.kd, rate=args.rate)
            level = tuned.level
            print(f'{PROG}: preset level {level:.3f} N, tuned on the nominal load at Kp '
                  f'{args.kp:g} N m/rad (the level of least drift, '
                  f'{tuned.drift * 1e3:.2f} mm in 1 s)', flush=True)
        return Preset(setup, scenario.gravity, level)
    if args.controller == 'impedance':
        return Squeeze(setup, scenario.gravity, args.squeeze_depth * 1e-3)
    return None


def _predicted(message: str) -> list[np.ndarray] | None:
    """Contact forces on the object in base axes [N] from the node's ~/solve JSON."""
    try:
        doc = json.loads(message)
        out = []
        for c in doc['contacts']:
            if c['wrench'] is None:
                return None
            x, z = np.array(c['tangent']), np.array(c['normal'])
            R = np.column_stack((x, np.cross(z, x), z))
            out.append(R @ np.array(c['wrench'][:3]))
        return out
    except (ValueError, KeyError, TypeError):
        return None


def _run(args: argparse.Namespace, scenario, setup, hsim, baseline) -> int:
    from grasp_torque_opt.ros.node import NODE_NAME
    import rclpy

    link = _Link(args, setup, hsim, baseline)
    m = len(link.names)
    disturbed = describe(args)
    print(f'{PROG}: {Path(scenario.source).name} in MuJoCo {_mujoco_version()}, {m} joints, '
          f'1 kHz physics, joint states at {args.rate:g} Hz, impedance Kp {args.kp:g} N m/rad '
          f'Kd {args.kd:g} N m s/rad, controller {args.controller}'
          + (f'; {disturbed}' if disturbed else ''), flush=True)
    deadline = time.monotonic() + args.wait
    while baseline is None and link.js_pub.get_subscription_count() == 0 and \
            time.monotonic() < deadline:
        rclpy.spin_once(link.node, timeout_sec=0.1)
    if baseline is None and link.js_pub.get_subscription_count() == 0:
        print(f'{PROG}: no {NODE_NAME} is listening on joint_states (start one, or '
              'use --with-node)', file=sys.stderr)
        return link.close(1)

    # 1. Fingers held at the grasp configuration (as a driver's position mode would),
    #    object pinned, until the node commands.
    hsim.hold_joints = baseline is None
    reference = getattr(baseline, 'reference', None)
    if reference is not None:  # position control: the driver's reference is the target
        hsim.q_ref = reference(hsim.q_ref)
    if not link.run_for(args.wait, until=lambda: link.state['commands'] > 0):
        print(f'{PROG}: no effort command from {NODE_NAME} within {args.wait:g} s',
              file=sys.stderr)
        return link.close(1)
    # 2. The commands press the fingers on the pinned object, then it is let go.
    link.ask_prediction()
    link.run_for(args.settle)
    hsim.release()
    if reference is not None:
        hsim.q_ref = reference(hsim.q_ref)
    t_release_wall = time.monotonic()
    counted_at_release = link.state['commands']
    # 3. The object held (or not) for --duration, a line a second.
    track = _Track(args, scenario, setup, link, disturbed)
    link.run_for(args.duration, until=track.watch, each_second=track.every_second)
    track.every_second()
    wall = time.monotonic() - t_release_wall
    commands = link.state['commands'] - counted_at_release
    held, summary = _summary(args, track, commands, wall, link.state['malformed'])
    print(summary)
    if not args.no_picture:
        print(_picture(hsim, args.picture, link.state['predicted']))
        print(_plot(args, scenario, track.trace, baseline is None))
    return link.close(0 if held and commands > 0 else 1)


class _Link:
    """
    The driver's ROS side and its real-time loop.

    Its node publishes the simulated hand's joint states, IMU and (``--contacts``) the
    contacts; it takes the effort commands (or the baseline's) and the node's ~/solve
    predictions, and steps the simulation in real time.
    """

    def __init__(self, args: argparse.Namespace, setup, hsim, baseline) -> None:
        from geometry_msgs.msg import PoseArray
        from grasp_torque_opt.ros.node import COMMAND_QOS, NODE_NAME, SERVICE_QOS
        import rclpy
        from rclpy.qos import qos_profile_sensor_data
        from sensor_msgs.msg import Imu, JointState
        from std_msgs.msg import Float64MultiArray
        from std_srvs.srv import Trigger

        self.args, self.setup, self.hsim, self.baseline = args, setup, hsim, baseline
        self.names = list(hsim.sim.joints)
        rclpy.init()
        node = self.node = rclpy.create_node('grasp_sim_driver')
        self.js_pub = node.create_publisher(JointState, 'joint_states', qos_profile_sensor_data)
        self.contacts_pub = node.create_publisher(PoseArray, 'contacts',
                                                  qos_profile_sensor_data)
        self.imu_pub = node.create_publisher(Imu, 'imu', qos_profile_sensor_data)
        self.solve = node.create_client(Trigger, f'{NODE_NAME}/solve', qos_profile=SERVICE_QOS)
        self.state = {'command': None, 'commands': 0, 'malformed': 0, 'predicted': None,
                      'pending': None}
        node.create_subscription(Float64MultiArray, 'effort_commands', self.on_command,
                                 COMMAND_QOS)

    def on_command(self, msg) -> None:
        cmd = np.array(msg.data, dtype=float)
        if cmd.shape != (len(self.names),) or not np.all(np.isfinite(cmd)):
            self.state['malformed'] += 1
            return
        self.state['command'] = cmd
        self.state['commands'] += 1

    def close(self, code: int) -> int:
        import rclpy

        self.node.destroy_node()
        rclpy.try_shutdown()
        return code

    def ask_prediction(self) -> None:
        from std_srvs.srv import Trigger

        if self.state['pending'] is None and self.solve.service_is_ready():
            self.state['pending'] = self.solve.call_async(Trigger.Request())

    def take_prediction(self) -> None:
        future = self.state['pending']
        if future is not None and future.done():
            self.state['pending'] = None
            result = future.result()
            if result is not None and result.success:
                self.state['predicted'] = _predicted(result.message) or self.state['predicted']

    def publish(self) -> None:
        from geometry_msgs.msg import Pose, PoseArray
        from grasp_torque_opt.core.grasp_maps import compute_grasp_maps
        from grasp_torque_opt.ros.sim_topics import imu_message, publish_contacts
        from sensor_msgs.msg import Imu, JointState
        from std_msgs.msg import Float64MultiArray

        hsim, hand = self.hsim, self.setup.hand
        stamp = self.node.get_clock().now().to_msg()
        js = JointState(name=self.names, position=[float(x) for x in hsim.reading],
                        velocity=[float(x) for x in hsim.qdot],
                        effort=[float(x) for x in hsim.reported_effort()])
        js.header.stamp = stamp
        self.js_pub.publish(js)
        self.imu_pub.publish(imu_message(Imu, *hsim.imu(), hand.base_frame, stamp))
        if self.baseline is not None:  # the driver's own controller, on what it publishes
            self.on_command(Float64MultiArray(data=[float(x)
                                                    for x in self.baseline(hsim.reading)]))
        if self.args.contacts:
            # In the root frame (MuJoCo's world), where the simulated contacts are read.
            publish_contacts(hsim, self.setup, self.contacts_pub, hand.root_frame, stamp,
                             compute_grasp_maps, Pose, PoseArray)

    def run_for(self, seconds: float, until=None, each_second=None) -> bool:
        """Step in real time; publish joint states, apply commands; stop early on until()."""
        import rclpy

        hsim, state = self.hsim, self.state
        dt = hsim.model.opt.timestep
        period = 1.0 / self.args.rate
        t0_wall, t0_sim = time.monotonic(), hsim.time
        next_pub, next_second = t0_wall, t0_wall + 1.0
        while (now := time.monotonic()) < t0_wall + seconds:
            if state['command'] is not None:
                hsim.command = state['command']
                hsim.hold_joints = False
            behind = round((now - t0_wall - (hsim.time - t0_sim)) / dt)
            if behind > 0:
                hsim.step(min(behind, 20))  # at most 20 ms per pass, then catch up
            if now >= next_pub:
                next_pub += period
                self.publish()
            if until is not None and until():
                return True
            if each_second is not None and now >= next_second:
                next_second += 1.0
                each_second()
            wait = min(next_pub, t0_wall + seconds) - time.monotonic()
            rclpy.spin_once(self.node, timeout_sec=max(0.0, wait))
            self.take_prediction()
        return False


class _Track:
    """
    The object after release: its drift, lost contacts, force errors, friction usage.

    ~/solve predicts for the scenario's mass and pose, asked once a second: against a
    disturbed run its forces are a reference, not a prediction to score.
    """

    def __init__(self, args: argparse.Namespace, scenario, setup, link: _Link,
                 disturbed: str) -> None:
        self.args, self.setup, self.link, self.hsim = args, setup, link, link.hsim
        self.mu = scenario.friction.mu1, scenario.friction.mu2
        self.disturbed = disturbed
        self.sim_release = self.hsim.time
        self.limit = args.drift_limit * 1e-3
        self.passed: float | None = None
        self.max_drift = 0.0
        self.lost: dict[str, float] = {}
        self.errors: list[float] = []
        self.usage: list[float] = []
        self.trace: list[tuple[float, float, float]] = []

    def every_second(self) -> None:
        """Print the line of the second: drift, rotation, forces against the prediction."""
        from grasp_torque_opt.sim.simulator import friction_usage

        hsim = self.hsim
        t = hsim.time - self.sim_release
        drift, rotation = hsim.motion()
        readings, unplanned = hsim.readings()
        pred = self.link.state['predicted']
        parts = [f't={t:4.1f} s  drift {drift * 1e3:7.3f} mm  rotation '
                 f'{np.degrees(rotation):6.3f} deg']
        forces, usage = [], []
        for i, r in enumerate(readings):
            if not r.touching:
                self.lost.setdefault(self.setup.contacts[i].link, t)
                forces.append('-/' + (f'{np.linalg.norm(pred[i]):.2f}' if pred else '?'))
                continue
            forces.append(f'{np.linalg.norm(r.force):.2f}/'
                          + (f'{np.linalg.norm(pred[i]):.2f}' if pred else '?'))
            normal = r.normal
            fn = float(r.force @ normal)
            ft = float(np.linalg.norm(r.force - fn * normal))
            usage.append(friction_usage(np.array([ft, 0.0, fn, float(r.torque @ normal)]),
                                        *self.mu))
        parts.append('forces sim/pred [N] ' + ' '.join(forces))
        if pred and all(r.touching for r in readings) and not self.disturbed:
            err = max(np.linalg.norm(r.force - p) / np.linalg.norm(p)
                      for r, p in zip(readings, pred))
            self.errors.append(err)
            parts.append(f'(max error {100 * err:.1f}%)')
        if usage:
            self.usage.append(max(usage))
            parts.append('friction (planned cone) ' + ' '.join(f'{100 * u:.0f}' for u in usage)
                         + ' %')
        if unplanned > 1e-3:
            parts.append(f'other contacts {unplanned:.2f} N')
        print('  '.join(parts), flush=True)
        self.link.ask_prediction()

    def watch(self) -> bool:
        """Record the drift and the trace; tell whether the object fell."""
        hsim = self.hsim
        drift, _ = hsim.motion()
        self.max_drift = max(self.max_drift, drift)
        t = hsim.time - self.sim_release
        if not self.trace or t - self.trace[-1][0] >= 1.0 / self.args.rate:
            applied = hsim.effort()
            self.trace.append((t, drift, float(np.sqrt(np.mean(applied ** 2)))))
        if drift > self.limit and self.passed is None:
            self.passed = hsim.time - self.sim_release
        return drift > max(20e-3, 10 * self.limit)  # fallen: no point in going on


def _summary(args: argparse.Namespace, track: _Track, commands: int, wall: float,
             malformed: int) -> tuple[bool, str]:
    """Return whether the object was held, and the summary line that says why."""
    hsim = track.hsim
    simulated = hsim.time - track.sim_release
    drift, rotation = hsim.motion()
    held = track.passed is None
    if held:
        why = (f'held: drift {drift * 1e3:.3f} mm, rotation {np.degrees(rotation):.3f} deg '
               f'after {simulated:.1f} s (limit {args.drift_limit:g} mm)')
    else:
        why = (f'NOT held: drift passed {args.drift_limit:g} mm at t = {track.passed:.2f} s'
               f', {track.max_drift * 1e3:.1f} mm at most')
        if track.lost:
            first = min(track.lost, key=track.lost.get)
            why += f'; contact lost first at {first}'
        why += ('; the torques did not hold the object with this impedance and friction'
                if commands else '; no command arrived after release')
    extra = []
    if track.errors:
        extra.append(f"contact forces within {100 * max(track.errors):.1f}% of the node's "
                     'predicted wrenches')
    elif track.disturbed:
        extra.append("contact forces not scored against the node's ~/solve (it plans for "
                     "the scenario's mass and pose, asked once a second): the run was "
                     'disturbed')
    if track.usage:
        extra.append(f'friction usage up to {100 * max(track.usage):.0f}% of the planned '
                     "cone (MuJoCo's elliptic cone is wider)")
    extra.append(f'{commands} commands ({commands / max(wall, 1e-9):.0f}/s, malformed '
                 f'{malformed})')
    extra.append(f'real-time factor {simulated / max(wall, 1e-9):.2f}')
    why += f'; mean effort {hsim.mean_effort():.4f} N m (RMS joint torque)'
    return held, 'summary: ' + why + '; ' + '; '.join(extra)


def _mujoco_version() -> str:
    import mujoco

    return mujoco.__version__


def _plot(args: argparse.Namespace, scenario, trace: list, node: bool) -> str:
    """Run the baseline on the same disturbances, plot both runs; return the line to print."""
    from grasp_torque_opt.ros.sim_compare import baseline_trace
    from grasp_torque_opt.sim.model import SimSettings
    from grasp_torque_opt.sim.plot import PLOT_CAPTION, plot_runs

    sim = SimSettings(mu_tangential=args.mu_tangential, mu_torsional=args.mu_torsional)
    base = baseline_trace(scenario, rig_settings(args), sim)
    label = 'this run: the node over ROS, on its params file' if node else \
        f'this run: {args.controller}'
    if not base:
        outcome = 'did not run'
    elif base[-1][0] < args.duration - 2.0 / args.rate:  # it stopped early: fallen
        outcome = f'dropped the ball at t = {base[-1][0]:.2f} s'
    else:
        outcome = f'drifted {1e3 * base[-1][1]:.3f} mm'
    title = f"{describe(args) or 'no disturbance'}, Kp {args.kp:g} N m/rad"
    try:
        written = plot_runs(args.plot, {
            label: trace,
            f'baseline: the node told only the scenario (no IMU, no measured efforts, '
            f'friction margin k = 0, i.e. the full cone), {outcome}': base},
            title, args.drift_limit)
    except OSError as e:
        return f'plot: not written, cannot write {args.plot}: {e.strerror}'
    return f'plot: {written.resolve()} ({PLOT_CAPTION}; the baseline {outcome})'


def _picture(hsim, path: str, predicted) -> str:
    from grasp_torque_opt.sim.render import CAPTION, render_grasp, RenderUnavailable

    try:
        written = render_grasp(hsim, path, predicted)
    except RenderUnavailable as e:
        return f'picture: not written, offscreen rendering is unavailable ({e})'
    except OSError as e:
        return f'picture: not written, cannot write {path}: {e.strerror}'
    return f'picture: {written.resolve()} ({CAPTION})'


if __name__ == '__main__':
    sys.exit(main())
