# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
A demo driver that needs no robot: it plays a scenario as a hand would.

It publishes joint states (the scenario's grasp with a small sinusoidal motion,
NaN efforts as joint_state_broadcaster sends them), the contact frames at the
current configuration and the scenario's load; it listens to
``effort_commands`` and ``/diagnostics`` and prints a live line a second (command
rate, solve time, torque norm, status), then a summary.

``--with-node`` starts ``grasp_torque_node`` in a child process first, on a
private ROS domain with localhost-only discovery, and stops it at the end.
``--watch`` creates no publisher and prints the live line of a node already
running (on the current ROS_DOMAIN_ID) for ``--duration`` seconds: a way to see
what it does without RViz. It follows a remapped node with the same remap
(``--ros-args -r effort_commands:=/effort_controller/commands``) or by its name
(``--node /right_hand/grasp_torque_node``: the topic that node publishes its
commands on, found in the ROS graph). Ctrl-C ends it quietly.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import sys
import time

from grasp_torque_opt.core.command_line import add_version, EXIT_INTERRUPTED, HelpFormatter
from grasp_torque_opt.ros.node_process import (
    isolate, node_process, scenario_of, startup_failure)
import numpy as np


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog='grasp-torque-demo', formatter_class=HelpFormatter,
                                description=__doc__.strip(), epilog=(
                                    'exit codes: 0 certified commands flowed (--watch: the '
                                    'watch ended), 1 none or malformed ones, 2 bad input. '
                                    'docs/node.md'))
    add_version(p)
    p.add_argument('--params', default='allegro_right_node.yaml',
                   help='node params file (bundled name or path); its scenario is played')
    p.add_argument('--duration', type=float, default=5.0, help='seconds to play [s]')
    p.add_argument('--rate', type=float, default=200.0, help='joint state rate [Hz]')
    p.add_argument('--amplitude', type=float, default=0.01, help='joint motion [rad]')
    p.add_argument('--with-node', action='store_true',
                   help='start grasp_torque_node in a child process')
    p.add_argument('--watch', action='store_true',
                   help='publish nothing: only print what a running node does '
                        '(on the current ROS_DOMAIN_ID)')
    p.add_argument('--node', metavar='NAME',
                   help='--watch: follow this node (e.g. /right_hand/grasp_torque_node): '
                        'its commands on whatever topic it publishes them, its diagnostics')
    return p


def main(argv: list[str] | None = None) -> int:
    """
    Run the demo; exit code 0 when certified commands flowed and all were well-formed.

    ``argv`` is the whole command line with the program's name (None: ``sys.argv``);
    what follows ``--ros-args`` goes to rclpy (remaps, a node name).
    """
    from rclpy.utilities import remove_ros_args

    argv = sys.argv if argv is None else argv
    args = _parser().parse_args(remove_ros_args(argv)[1:])
    args.ros_argv = list(argv)
    if args.node and not args.watch:
        print('grasp-torque-demo: error: --node is for --watch', file=sys.stderr)
        return 2
    if args.with_node and args.watch:
        print('grasp-torque-demo: error: --watch and --with-node exclude each other',
              file=sys.stderr)
        return 2
    if not args.watch:
        isolate()
    from grasp_torque_opt.core.exceptions import InputError
    from grasp_torque_opt.core.resources import find_config

    try:
        params = find_config(args.params, '--params')
        scenario = find_config(scenario_of(params))
    except InputError as e:
        print(f'grasp-torque-demo: error: {e}', file=sys.stderr)
        return 2
    try:
        with node_process(params, args.with_node) as child:
            return _play(args, scenario, child)
    except KeyboardInterrupt:  # Ctrl-C: a watch, or a demo, stopped by hand
        return EXIT_INTERRUPTED


def _play(args: argparse.Namespace, scenario: Path, child=None) -> int:
    from grasp_torque_opt.core.grasp_setup import GraspSetup
    import rclpy
    from rclpy.executors import ExternalShutdownException

    setup = GraspSetup.from_file(scenario)
    rclpy.init(args=args.ros_argv)
    node = rclpy.create_node('grasp_demo_driver')
    # The executor rclpy.spin_once uses, made now: a Ctrl-C inside its construction (at
    # the first spin) left a half-made executor whose __del__ printed a traceback.
    rclpy.get_global_executor()
    try:
        return _spin(args, scenario, node, setup, child)
    except (KeyboardInterrupt, ExternalShutdownException):
        print('grasp-torque-demo: interrupted', file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def _commands_topic(node, name: str, until: float) -> str | None:
    """Return the topic a node publishes its effort commands on, waited for until ``until``."""
    import rclpy

    ns, _, base = name.rstrip('/').rpartition('/')
    ns = ns or '/'
    while time.monotonic() < until:
        try:
            topics = node.get_publisher_names_and_types_by_node(base, ns)
        except Exception:  # noqa: B902 -- rclpy raises NodeNameNonExistentError until it is up
            topics = []
        for topic, types in topics:
            if 'std_msgs/msg/Float64MultiArray' in types:
                return topic
        rclpy.spin_once(node, timeout_sec=0.1)
    return None


def _spin(args: argparse.Namespace, scenario: Path, node, setup, child=None) -> int:
    from diagnostic_msgs.msg import DiagnosticArray
    from geometry_msgs.msg import PoseArray, WrenchStamped
    from grasp_torque_opt.ros.node import COMMAND_QOS
    import rclpy
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import JointState
    from std_msgs.msg import Float64MultiArray

    hand = setup.hand
    names = hand.one_dof_joints(hand.model)
    idx_q = [hand.model.joints[hand.model.getJointId(n)].idx_q for n in names]
    publishers = None
    if not args.watch:  # a watch publishes nothing
        js_pub = node.create_publisher(JointState, 'joint_states', qos_profile_sensor_data)
        contacts_pub = node.create_publisher(PoseArray, 'contacts', qos_profile_sensor_data)
        wrench_pub = node.create_publisher(WrenchStamped, 'external_wrench',
                                           qos_profile_sensor_data)
        publishers = (js_pub, contacts_pub, wrench_pub)
    watched = (args.node or 'grasp_torque_node').rstrip('/').rpartition('/')[2]
    heard = _Heard(hand.torque_limits, watched)

    domain = os.environ.get('ROS_DOMAIN_ID', '0')
    topic = 'effort_commands'
    start = time.monotonic()
    if args.node:
        topic = _commands_topic(node, args.node, start + args.duration)
        if topic is None:
            print(f'grasp-torque-demo: no node {args.node} publishing effort commands on '
                  f'ROS_DOMAIN_ID {domain} within {args.duration:g} s', file=sys.stderr)
            return 1
    sub = node.create_subscription(Float64MultiArray, topic, heard.on_command, COMMAND_QOS)
    node.create_subscription(DiagnosticArray, '/diagnostics', heard.on_diagnostics, 10)

    if args.watch:
        print(f'grasp-torque-demo: watching {sub.topic_name} and /diagnostics for '
              f'{args.duration:g} s (ROS_DOMAIN_ID {domain})', flush=True)
    else:
        print(f'grasp-torque-demo: {scenario.name}, {hand.m} joints, joint states at '
              f'{args.rate:g} Hz for {args.duration:g} s (ROS_DOMAIN_ID {domain})')
    deadline = time.monotonic() + 30.0
    while not args.watch and node.count_subscribers('joint_states') == 0 and \
            time.monotonic() < deadline and not startup_failure(child):
        rclpy.spin_once(node, timeout_sec=0.1)
    if startup_failure(child):  # the node's own error, not "no node"
        print(f'grasp-torque-demo: {startup_failure(child)}', file=sys.stderr)
        return 1
    if not args.watch and node.count_subscribers('joint_states') == 0:
        print('grasp-torque-demo: no grasp_torque_node is listening on joint_states',
              file=sys.stderr)
        return 1

    if not args.watch:
        # The node takes input only after its start-up check for a namesake on the domain
        # (startup_check_time): the grasp at rest until its first command, then the play.
        rest = JointState(name=list(names), position=[float(setup.q[i]) for i in idx_q],
                          effort=[float('nan')] * len(names))
        while not heard.received and time.monotonic() < deadline:
            rest.header.stamp = node.get_clock().now().to_msg()
            js_pub.publish(rest)
            rclpy.spin_once(node, timeout_sec=1.0 / args.rate)
        heard.received.clear()
    played = _play_for(args, node, setup, heard, publishers,
                       start if args.watch else time.monotonic())
    end = time.monotonic() + 0.2  # the last commands in flight
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.02)
    _print_summary(args, heard, played)
    return 0 if (heard.received or args.watch) and heard.bad == 0 else 1


class _Heard:
    """What the demo hears: the commands (checked against the limits), the node's diagnostics."""

    def __init__(self, limits: np.ndarray, watched: str) -> None:
        self.limits = limits
        self.watched = watched  # the node's own name, without its namespace
        self.received: list[tuple[float, np.ndarray]] = []
        self.diag: dict[str, str] = {}
        self.solve_times: list[float] = []
        self.bad = 0

    def on_command(self, msg) -> None:
        cmd = np.array(msg.data)
        if cmd.shape != self.limits.shape or not np.all(np.isfinite(cmd)) or \
                np.any(np.abs(cmd) > self.limits):
            self.bad += 1
        self.received.append((time.monotonic(), cmd))

    def on_diagnostics(self, msg) -> None:
        for status in msg.status:
            # The node's fully qualified name, then ': grasp torques'.
            if status.name.partition(': ')[0].rpartition('/')[2] == self.watched:
                self.diag.clear()
                self.diag.update({kv.key: kv.value for kv in status.values})
                self.diag['message'] = status.message
                if 'solve_time_s' in self.diag:
                    self.solve_times.append(float(self.diag['solve_time_s']))


def _play_for(args: argparse.Namespace, node, setup, heard: _Heard, publishers,
              t0: float) -> dict[str, str]:
    """
    Play (or watch) for ``--duration`` from ``t0``, printing the live line a second.

    Joint states at ``--rate``, contacts and load at 50 Hz, unless a watch
    (``publishers`` None). Returns the node's diagnostics while joint states flowed.
    """
    import rclpy

    hand = setup.hand
    names = hand.one_dof_joints(hand.model)
    idx_q = [hand.model.joints[hand.model.getJointId(n)].idx_q for n in names]
    period = 1.0 / args.rate
    next_tick, next_print, next_slow = t0, t0 + 1.0, t0
    last_count = 0
    q = setup.q.copy()
    while (now := time.monotonic()) < t0 + args.duration:
        if now >= next_tick and not args.watch:
            next_tick += period
            t = now - t0
            for k, iq in enumerate(idx_q):
                q[iq] = setup.q[iq] + args.amplitude * np.sin(2 * np.pi * 0.5 * t + 0.4 * k)
            stamp = _publish_joint_state(node, publishers[0], names, [float(q[i]) for i in idx_q])
            if now >= next_slow:  # contacts and load at 50 Hz
                next_slow += 0.02
                _publish_contacts_and_load(publishers[1:], setup, q, stamp)
        if now >= next_print:
            next_print += 1.0
            n = len(heard.received) - last_count
            last_count = len(heard.received)
            norm = np.linalg.norm(heard.received[-1][1]) if heard.received else float('nan')
            solve_ms = 1e3 * float(heard.diag.get('solve_time_s', 'nan'))
            if args.watch:
                next_tick = next_print
            print(f't={now - t0:4.1f} s  commands {n:4d}/s  solve {solve_ms:6.3f} ms  '
                  f"|command| {norm:.4f} N m  status {heard.diag.get('status', '-')}  "
                  f"fault {heard.diag.get('fault', '-')}", flush=True)
        rclpy.spin_once(node, timeout_sec=max(0.0, min(next_tick, next_print) - time.monotonic()))
    return dict(heard.diag)  # the node's state while joint states flowed


def _publish_joint_state(node, js_pub, names: list[str], positions: list[float]):
    """Publish the joint states, NaN efforts as joint_state_broadcaster sends them; its stamp."""
    from sensor_msgs.msg import JointState

    js = JointState(name=list(names), position=positions, effort=[float('nan')] * len(names))
    js.header.stamp = node.get_clock().now().to_msg()
    js_pub.publish(js)
    return js.header.stamp


def _publish_contacts_and_load(publishers, setup, q: np.ndarray, stamp) -> None:
    """Publish the contact frames at configuration q and the scenario's load, base axes."""
    from geometry_msgs.msg import Pose, PoseArray, WrenchStamped
    from grasp_torque_opt.core.grasp_maps import compute_grasp_maps
    import pinocchio as pin

    contacts_pub, wrench_pub = publishers
    hand = setup.hand
    base = hand.base_frame
    maps = compute_grasp_maps(hand, q, setup.contacts, setup.object_origin)
    poses = PoseArray()
    poses.header.frame_id, poses.header.stamp = base, stamp
    for frame in maps.contacts:
        x, y, z, w = pin.Quaternion(frame.rotation).coeffs()
        pose = Pose()
        pose.position.x, pose.position.y, pose.position.z = map(float, frame.position)
        pose.orientation.x, pose.orientation.y = float(x), float(y)
        pose.orientation.z, pose.orientation.w = float(z), float(w)
        poses.poses.append(pose)
    contacts_pub.publish(poses)
    ws = WrenchStamped()
    ws.header.frame_id, ws.header.stamp = base, stamp
    F, M = setup.external_wrench[:3], setup.external_wrench[3:]
    ws.wrench.force.x, ws.wrench.force.y, ws.wrench.force.z = map(float, F)
    ws.wrench.torque.x, ws.wrench.torque.y, ws.wrench.torque.z = map(float, M)
    wrench_pub.publish(ws)


def _print_summary(args: argparse.Namespace, heard: _Heard, played: dict[str, str]) -> None:
    """Print the summary line: commands, malformed ones, |command|, solve time, the node's."""
    received, solve_times = heard.received, heard.solve_times
    sent = '' if args.watch else f' for about {int(args.duration * args.rate)} joint states'
    norms = [np.linalg.norm(c) for _, c in received]
    print(f'summary: {len(received)} commands{sent} '
          f'({len(received) / args.duration:.1f}/s); malformed {heard.bad}; '
          + (f'|command| {min(norms):.4f} to {max(norms):.4f} N m; ' if norms else '')
          + (f'solve time median {1e3 * np.median(solve_times):.3f} ms (diagnostics); '
             if solve_times else '')
          + f"node cycles {played.get('cycles', '-')}, faults {played.get('faults', '-')}, "
          f"rejected joint states {played.get('rejected.joint_states', '-')}, "
          f"last status {played.get('status', '-')}")


if __name__ == '__main__':
    sys.exit(main())
