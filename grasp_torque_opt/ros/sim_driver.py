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
from grasp_torque_opt.ros import sim_commands
from grasp_torque_opt.ros.node_process import (
    isolate, node_process, scenario_of, startup_failure)
from grasp_torque_opt.ros.sim_options import (
    check, describe, friction, parser, PROG, rig_settings)
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
    from grasp_torque_opt.sim.drivers import attach
    from grasp_torque_opt.sim.episode import simulated
    from grasp_torque_opt.sim.model import SimSettings

    if args.plan is not None:
        return _simulate_best(args)
    if args.with_node:
        isolate()
    try:
        params = find_config(args.params, '--params')
        scenario = load_scenario(find_config(scenario_of(params)))
        mu_tangential, mu_torsional = friction(args, scenario)
        setup, rig = simulated(scenario, rig_settings(args), sim=SimSettings(
            mu_tangential=mu_tangential, mu_torsional=mu_torsional, touch=args.tactile))
        baseline = _baseline(args, scenario, setup)
        driver = sim_commands.settings(args)
        if driver.kind != 'effort':  # the effort driver is the rig itself
            attach(rig, driver)
    except (InputError, ValueError) as e:
        print(f'{PROG}: error: {e}', file=sys.stderr)
        return 2
    try:
        told = () if args.effort_report == 'applied' else (  # the node told what they are
            'effort_estimation.driver_stiffness:=' + repr(float(args.kp)),
            'effort_estimation.effort_report:=commanded')
        arguments = (*sim_commands.node_arguments(driver), *_tactile_params(args, setup),
                     *(a for o in (*_lockstep_overrides(args), *told) for a in ('-p', o)))
        with node_process(params, args.with_node, arguments) as child:
            return _run(args, scenario, setup, rig, baseline, child)
    except KeyboardInterrupt:
        print(f'{PROG}: interrupted', file=sys.stderr)
        return EXIT_INTERRUPTED


#: The node's parameters in --lockstep (docs/simulation.md, "Lockstep"): simulated time,
#: the stamped command that names the joint state it answers, and the schema's largest
#: cycle budget and joint state timeout, so that no solver is cut by the wall clock.
LOCKSTEP_PARAMETERS = ('use_sim_time:=true', 'age_on_sim_time:=true',
                       'publish_stamped_command:=true',
                       'cycle_budget:=1.0', 'joint_state_timeout:=10.0')

#: How long lockstep waits for the node's answer to a joint state [s, wall clock].
LOCKSTEP_WAIT = 2.0


def _lockstep_overrides(args: argparse.Namespace) -> tuple[str, ...]:
    """Return the parameters given to the child node: lockstep's, or none."""
    return LOCKSTEP_PARAMETERS if args.lockstep else ()


def _simulate_best(args: argparse.Namespace) -> int:
    """Simulate the best candidate of --plan by --scores: the planner's loop's last step."""
    from grasp_torque_opt.core.exceptions import InputError
    from grasp_torque_opt.core.resources import find_config
    from grasp_torque_opt.core.scenario import load_scenario
    from grasp_torque_opt.ros.sim_plan import run
    from grasp_torque_opt.sim.model import SimSettings

    try:
        base = find_config(scenario_of(find_config(args.params, '--params')))
        mu_tangential, mu_torsional = friction(args, load_scenario(base))
        return run(args, base, rig_settings(args), SimSettings(
            mu_tangential=mu_tangential, mu_torsional=mu_torsional))
    except (InputError, ValueError) as e:
        print(f'{PROG}: error: {e}', file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f'{PROG}: interrupted', file=sys.stderr)
        return EXIT_INTERRUPTED


def _tactile_params(args: argparse.Namespace, setup) -> list[str]:
    """Return the node's parameters that read ``--tactile``'s array (and say them)."""
    if not args.tactile:
        return []
    links = ','.join(c.link for c in setup.contacts)
    print(f"{PROG}: touch sensors on 'tactile', one per contact; the node reads them with "
          f'tactile.source array, tactile.links [{links}]', flush=True)
    return ['-p', 'tactile.source:=array', '-p', f'tactile.links:=[{links}]']


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


def _run(args: argparse.Namespace, scenario, setup, hsim, baseline, child=None) -> int:
    from grasp_torque_opt.ros.node import NODE_NAME
    import rclpy

    link = _Link(args, setup, hsim, baseline)
    m = len(link.names)
    disturbed = describe(args)
    print(f'{PROG}: {Path(scenario.source).name} in MuJoCo {_mujoco_version()}, {m} joints, '
          f'1 kHz physics, joint states at {args.rate:g} Hz, '
          f'{sim_commands.describe(sim_commands.settings(args))}, controller {args.controller}'
          + (f'; {disturbed}' if disturbed else ''), flush=True)
    deadline = time.monotonic() + args.wait
    while baseline is None and link.js_pub.get_subscription_count() == 0 and \
            time.monotonic() < deadline and not startup_failure(child):
        rclpy.spin_once(link.node, timeout_sec=0.1)
    if startup_failure(child):  # the node's own error, not "no node"
        print(f'{PROG}: {startup_failure(child)}', file=sys.stderr)
        return link.close(1)
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
        from std_srvs.srv import Trigger

        self.args, self.setup, self.hsim, self.baseline = args, setup, hsim, baseline
        self.names = list(hsim.sim.joints)
        rclpy.init()
        node = self.node = rclpy.create_node('grasp_sim_driver')
        self.js_pub = node.create_publisher(JointState, 'joint_states', qos_profile_sensor_data)
        self.contacts_pub = node.create_publisher(PoseArray, 'contacts',
                                                  qos_profile_sensor_data)
        self.imu_pub = node.create_publisher(Imu, 'imu', qos_profile_sensor_data)
        if args.tactile:  # the contact links' touch sensors, in the contacts' order
            from std_msgs.msg import Float32MultiArray
            self.tactile_pub = node.create_publisher(Float32MultiArray, 'tactile',
                                                     qos_profile_sensor_data)
        self.solve = node.create_client(Trigger, f'{NODE_NAME}/solve', qos_profile=SERVICE_QOS)
        self.state = {'command': None, 'commands': 0, 'malformed': 0, 'predicted': None,
                      'pending': None}
        kind, topic = sim_commands.subscription(args.driver)
        node.create_subscription(kind, topic, self.on_command, COMMAND_QOS)
        if args.lockstep:
            self._lockstep_interfaces(NODE_NAME, COMMAND_QOS)

    def _lockstep_interfaces(self, node_name: str, qos) -> None:
        """--lockstep: /clock, and the stamped commands that name the joint state answered."""
        from rosgraph_msgs.msg import Clock
        from sensor_msgs.msg import JointState

        self.clock_pub = self.node.create_publisher(Clock, '/clock', 10)
        self.state.update(asked=None, unanswered=0)
        self.node.create_subscription(JointState, f'{node_name}/effort_commands_stamped',
                                      self.on_stamped, qos)

    def on_stamped(self, msg) -> None:
        """--lockstep: take the node's answer to the joint state last published, only."""
        stamp = (msg.header.stamp.sec, msg.header.stamp.nanosec)
        if stamp != self.state['asked']:
            return  # a late answer to an earlier joint state: not applied
        from std_msgs.msg import Float64MultiArray

        self.state['asked'] = None
        self.on_command(Float64MultiArray(data=list(msg.effort)), lockstep=False)

    def on_command(self, msg, lockstep: bool | None = None) -> None:
        if self.args.lockstep if lockstep is None else lockstep:
            return  # lockstep takes the stamped copy (on_stamped)
        cmd = sim_commands.command_of(msg, len(self.names))
        if cmd is None:
            self.state['malformed'] += 1
            return
        # The effort driver is the rig (the torque is its command); the others, a model.
        self.state['command'] = cmd[0] if self.hsim.driver is None else cmd
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
            if self.args.lockstep:  # answered while the simulation waits, not during a cycle
                import rclpy

                rclpy.spin_until_future_complete(self.node, self.state['pending'],
                                                 timeout_sec=LOCKSTEP_WAIT * 10)
                self.take_prediction()

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
        if self.args.lockstep:  # the simulation's time, on /clock and in the stamps
            from builtin_interfaces.msg import Time
            from rosgraph_msgs.msg import Clock

            ns = round(hsim.time * 1e9)
            stamp = Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)
            if self.state.get('clock') != ns:  # else on /clock since the step (tick)
                self.clock_pub.publish(Clock(clock=stamp))
            self.state['asked'] = (stamp.sec, stamp.nanosec)
        else:
            stamp = self.node.get_clock().now().to_msg()
        js = JointState(name=self.names, position=[float(x) for x in hsim.reading],
                        velocity=[float(x) for x in hsim.qdot],
                        effort=[float(x) for x in hsim.reported_effort()])
        js.header.stamp = stamp
        # Every other input before the joint state: the node's cycle on it uses them.
        self.imu_pub.publish(imu_message(Imu, *hsim.imu(), hand.base_frame, stamp))
        if self.args.tactile:
            from std_msgs.msg import Float32MultiArray
            self.tactile_pub.publish(Float32MultiArray(data=[float(x) for x in hsim.touch()]))
        if self.args.contacts:
            # In the root frame (MuJoCo's world), where the simulated contacts are read.
            publish_contacts(hsim, self.setup, self.contacts_pub, hand.root_frame, stamp,
                             compute_grasp_maps, Pose, PoseArray)
        self.js_pub.publish(js)
        if self.baseline is not None:  # the driver's own controller, on what it publishes
            self.on_command(Float64MultiArray(data=[float(x)
                                                    for x in self.baseline(hsim.reading)]),
                            lockstep=False)

    def run_for(self, seconds: float, until=None, each_second=None) -> bool:
        """Step in real time; publish joint states, apply commands; stop early on until()."""
        import rclpy

        if self.args.lockstep:
            return self.run_lockstep(seconds, until, each_second)

        hsim, state = self.hsim, self.state
        dt = hsim.model.opt.timestep
        period = 1.0 / self.args.rate
        t0_wall, t0_sim = time.monotonic(), hsim.time
        next_pub, next_second = t0_wall, t0_wall + 1.0
        while (now := time.monotonic()) < t0_wall + seconds:
            if state['command'] is not None:
                if hsim.driver is None:
                    hsim.command = state['command']
                else:
                    hsim.driver.receive(*state['command'])
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

    def tick(self) -> None:
        """
        --lockstep: publish the simulation's time on /clock as soon as it is stepped.

        Well before the joint state of that time, so that the node's clock has moved
        when the joint state comes (they are two topics: no order between them is sure).
        """
        from builtin_interfaces.msg import Time
        from rosgraph_msgs.msg import Clock

        ns = round(self.hsim.time * 1e9)
        self.clock_pub.publish(Clock(clock=Time(sec=ns // 1_000_000_000,
                                                nanosec=ns % 1_000_000_000)))
        self.state['clock'] = ns

    def answer(self, seconds: float) -> bool:
        """--lockstep: spin until the node answers the joint state published, or ``seconds``."""
        import rclpy

        deadline = time.monotonic() + seconds
        while self.state['asked'] is not None and (left := deadline - time.monotonic()) > 0:
            rclpy.spin_once(self.node, timeout_sec=min(left, 0.05))
        self.take_prediction()
        return self.state['asked'] is None

    def run_lockstep(self, seconds: float, until=None, each_second=None) -> bool:
        """
        Step in lockstep with the node: each joint state answered before the physics goes on.

        Simulated time advances by one joint state period per answer (or per
        ``LOCKSTEP_WAIT`` of the wall clock without one: the node published nothing, a
        fault, and the command in force stays). Before the first command the simulation
        waits (wall clock, up to ``seconds``) with its time stopped.
        """
        import rclpy

        hsim, state = self.hsim, self.state
        dt = hsim.model.opt.timestep
        steps = max(1, round(1.0 / (self.args.rate * dt)))
        if state['commands'] == 0:  # the node starts: simulated time stands still
            deadline = time.monotonic() + seconds
            while time.monotonic() < deadline:
                self.publish()
                if self.answer(LOCKSTEP_WAIT):
                    end = time.monotonic() + 0.2  # answers to its repeats: not taken
                    while time.monotonic() < end:
                        rclpy.spin_once(self.node, timeout_sec=0.05)
                    break
            return until is None or until()
        t_end, next_second = hsim.time + seconds - dt / 2, hsim.time + 1.0 - dt / 2
        while hsim.time < t_end:
            self.publish()
            if not self.answer(LOCKSTEP_WAIT):
                state['asked'] = None
                state['unanswered'] += 1
            if state['command'] is not None:
                hsim.command = state['command']
                hsim.hold_joints = False
            hsim.step(steps)
            self.tick()
            if until is not None and until():
                return True
            if each_second is not None and hsim.time >= next_second:
                next_second += 1.0
                each_second()
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
        self.printed_at: float | None = None

    def every_second(self) -> None:
        """Print the line of the second: drift, rotation, forces against the prediction."""
        from grasp_torque_opt.sim.simulator import friction_usage

        hsim = self.hsim
        if self.printed_at == hsim.time:  # lockstep's last second, already printed
            return
        self.printed_at = hsim.time
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
    turned = np.degrees(rotation) >= args.rotation_limit
    held = track.passed is None and not turned
    if held:
        why = (f'held: drift {drift * 1e3:.3f} mm, rotation {np.degrees(rotation):.3f} deg '
               f'after {simulated:.1f} s (limits {args.drift_limit:g} mm, '
               f'{args.rotation_limit:g} deg)')
    elif track.passed is None:
        why = (f'NOT held: rotation {np.degrees(rotation):.3f} deg after {simulated:.1f} s, '
               f'not under the rotation limit {args.rotation_limit:g} deg (drift '
               f'{drift * 1e3:.3f} mm, under its limit {args.drift_limit:g} mm)')
    else:
        why = (f'NOT held: drift passed {args.drift_limit:g} mm at t = {track.passed:.2f} s'
               f', {track.max_drift * 1e3:.1f} mm at most (at the end {drift * 1e3:.3f} mm, '
               f'rotation {np.degrees(rotation):.3f} deg)')
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
    if args.lockstep:
        extra.append(f"lockstep, {track.link.state['unanswered']} joint states unanswered")
    extra.append(f'real-time factor {simulated / max(wall, 1e-9):.2f}')
    why += f'; mean effort {hsim.mean_effort():.4f} N m (RMS joint torque)'
    return held, 'summary: ' + why + '; ' + '; '.join(extra)


def _mujoco_version() -> str:
    import mujoco

    return mujoco.__version__


def _plot(args: argparse.Namespace, scenario, trace: list, node: bool) -> str:
    """Run the baseline on the same disturbances, plot both runs; return the line to print."""
    from grasp_torque_opt.core.resources import find_config
    from grasp_torque_opt.ros.sim_compare import baseline_trace
    from grasp_torque_opt.sim.model import SimSettings
    from grasp_torque_opt.sim.plot import PLOT_CAPTION, plot_runs

    mu_tangential, mu_torsional = friction(args, scenario)
    sim = SimSettings(mu_tangential=mu_tangential, mu_torsional=mu_torsional)
    base = baseline_trace(scenario, rig_settings(args), sim, args.plot_baseline,
                          find_config(args.params, '--params'))
    label = (f'this run: the node over ROS on {Path(args.params).name}'
             + (' (lockstep)' if args.lockstep else '')) if node else \
        f'this run: {args.controller}'
    if not base:
        outcome = 'did not run'
    elif base[-1][0] < args.duration - 2.0 / args.rate:  # it stopped early: fallen
        outcome = f'dropped the ball at t = {base[-1][0]:.2f} s'
    else:
        outcome = f'drifted {1e3 * base[-1][1]:.3f} mm'
    title = f"{describe(args) or 'no disturbance'}, Kp {args.kp:g} N m/rad"
    try:
        written = plot_runs(args.plot, {label: trace, (
            'baseline: the same node with the object loop off (object_loop.enabled false: '
            "the scenario's load and the IMU's, no feedback from the ball's motion), "
            if args.plot_baseline == 'loop-off' else
            'baseline: the node told only the scenario (no IMU, no measured efforts, '
            'friction margin k = 0, i.e. the full cone), ') + outcome: base},
            title, args.drift_limit)
    except OSError as e:
        return f'plot: not written, cannot write {args.plot}: {e.strerror}'
    which = 'object loop off' if args.plot_baseline == 'loop-off' else 'scenario only'
    return f'plot: {written.resolve()} ({PLOT_CAPTION}; the baseline ({which}) {outcome})'


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
