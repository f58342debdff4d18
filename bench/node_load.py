# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The node under load: latency and dropped cycles of grasp_torque_node beside a trivial echo node.

Usage: .venv/bin/python bench/node_load.py [--duration 10] [--rates 500 1000]
       [--hands allegro planar] [--executors waitset single events] [--load-priority 0]
       [--out FILE]

For each hand, joint-state rate and rclpy executor, these answering processes
are measured in turn with the same load process:

- ``grasp_torque_node`` (``--executor E``, the hand's ``config/*_node.yaml``,
  ``publish_stamped_command:=true``), as configured (DAQP, the compiled cycle
  where it applies, normal scheduling), with ``thread_priority:=50`` (the spinning
  thread SCHED_FIFO 50 where the system allows; target ``grasp_torque_node/fifo``),
  with ``solver.compiled:=false`` (the Python cycle,
  target ``grasp_torque_node/python``) and with ``solver.backend:=proxsuite``
  ``solver.fallback:=daqp`` (target ``grasp_torque_node/proxsuite``, the default
  before DAQP's compiled cycle);
- an echo node written here, named ``grasp_torque_node`` too, that answers each
  joint state with zero torques on ``effort_commands`` and the stamped copy on
  ``~/effort_commands_stamped``: rclpy's own floor on this machine. It spins
  its executor as the node's main does (``events``: a ``spin_once`` loop; for
  ``waitset``, the node's own loop and its default, the echo stays on rclpy's
  SingleThreadedExecutor: the floor the node is held to), with
  normal scheduling (target ``echo``) and with SCHED_FIFO 50, the priority the
  node asks (target ``echo/fifo``).

The load process (a separate process, the same for every case) publishes joint
states with sensor-data QoS on absolute deadlines (the scenario's grasp with a
1 mrad motion), each stamped with its send time, and receives both command
topics (reliable, depth ``RECEIVER_DEPTH``: deeper than the node's 1, so that
the receiver never drops). A command is matched to its joint state by stamp;
a joint state of the measured window without a stamped command within the
drain time is a dropped cycle. Latency is stamp-to-receipt on the system clock.
The JSON keeps each dropped joint state's send time from the window's start
(``dropped_at_s``): a loss at the same phase of every second is a periodic
stall of the node (it found the 1 Hz diagnostics' half a millisecond).
With ``--load-priority 50`` the load process's spinning thread is SCHED_FIFO 50,
as the controller_manager loop that would send joint states and take the
commands on a ros2_control hand (the default: normal scheduling, as any process).
Every process runs on its own private ROS domain, localhost only; discovery,
the first command and 1 s of warm-up come before the measured window.

Speed is measured here, never asserted.
"""

from __future__ import annotations

import argparse
from datetime import datetime, timezone
import itertools
import json
import math
import os
from pathlib import Path
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ros_load import (  # noqa: E402
    Child,
    CONFIG,
    CpuShare,
    interrupt_on_signals,
    isolated_env,
    node_command,
    Pacer,
    percentiles_ms,
    private_domains,
    RECEIVER_DEPTH,
    set_stamp,
    stamp_ns,
    STAMPED_TOPIC,
    UniqueClock,
)

HANDS = {'allegro': ('allegro_right.yaml', 'allegro_right_node.yaml'),
         'planar': ('planar_two_finger.yaml', 'planar_two_finger_node.yaml')}
#: Answering nodes: the echo node, the node as configured (DAQP), and with ProxSuite.
TARGETS = ('echo', 'echo/fifo', 'grasp_torque_node', 'grasp_torque_node/fifo',
           'grasp_torque_node/python', 'grasp_torque_node/proxsuite')
#: The node's arguments added per target (the default: none).
TARGET_ARGS = {'grasp_torque_node/fifo': ['-p', 'thread_priority:=50'],
               'grasp_torque_node/python': ['-p', 'solver.compiled:=false'],
               'grasp_torque_node/proxsuite': ['-p', 'solver.backend:=proxsuite',
                                               '-p', 'solver.fallback:=daqp']}
WARMUP_S = 1.0
#: After the last joint state, how long commands in flight are still awaited [s].
DRAIN_S = 0.5
#: Longest wait for the answering node to be discovered, then to answer once [s].
READY_TIMEOUT_S = 10.0
#: Executors of the answering node. ``events`` is rclpy's EventsExecutor served by a
#: spin_once loop, as the node's main does (its spin() delivered no callback here).
EXECUTORS = ('waitset', 'single', 'events')
#: Amplitude of the joint motion around the scenario's grasp [rad].
AMPLITUDE = 1e-3


def _executor(name: str):
    """
    Give the echo's (or the load process's) executor for the node's ``--executor name``.

    ``waitset`` is the node's own loop: its echo stays on rclpy's SingleThreadedExecutor,
    rclpy's floor, the baseline issue 36 item 4 compares the node's default with.
    """
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.experimental import EventsExecutor
    return {'single': SingleThreadedExecutor, 'waitset': SingleThreadedExecutor,
            'events': EventsExecutor}[name]()


# -- the echo node ---------------------------------------------------------------------------

def echo_main(args: argparse.Namespace) -> int:
    """
    Run a minimal rclpy node that answers each joint state with zero torques, stamped.

    It takes joint states with sensor-data QoS (keep last 5), or with ``--echo-qos node``
    the node's own ``JOINT_STATE_QOS`` (keep last 1: a state that a newer one overtakes
    before it is taken is dropped, as in the node).
    """
    from grasp_torque_opt.ros.node import COMMAND_QOS, JOINT_STATE_QOS, NODE_NAME
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from rclpy.node import Node
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import JointState
    from std_msgs.msg import Float64MultiArray

    joints = args.joints.split(',')
    zeros = [0.0] * len(joints)
    rclpy.init()
    node = None
    try:
        node = Node(NODE_NAME)
        command_pub = node.create_publisher(Float64MultiArray, 'effort_commands', COMMAND_QOS)
        stamped_pub = node.create_publisher(JointState, '~/effort_commands_stamped',
                                            COMMAND_QOS)

        def on_joint_state(msg: JointState) -> None:
            command_pub.publish(Float64MultiArray(data=zeros))
            out = JointState(name=joints, effort=zeros)
            out.header.stamp = msg.header.stamp
            stamped_pub.publish(out)

        node.create_subscription(JointState, 'joint_states', on_joint_state,
                                 JOINT_STATE_QOS if args.echo_qos == 'node'
                                 else qos_profile_sensor_data)
        executor = _executor(args.executor)
        executor.add_node(node)
        if args.echo_priority:
            from grasp_torque_opt.ros.realtime import set_fifo

            print(f'echo executor thread: {set_fifo(args.echo_priority)[1]}', file=sys.stderr)
        if args.executor == 'events':  # as grasp_torque_node's main does
            while rclpy.ok():
                executor.spin_once(timeout_sec=1.0)
        else:
            executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


# -- the load process ------------------------------------------------------------------------

def load_main(args: argparse.Namespace) -> int:
    """Publish joint states at a fixed rate, receive the commands, write the figures as JSON."""
    from grasp_torque_opt.core.grasp_setup import GraspSetup
    import rclpy
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import JointState

    setup = GraspSetup.from_file(CONFIG / HANDS[args.hand][0])
    names = list(setup.hand.joints)

    rclpy.init(args=[sys.argv[0]])
    node = rclpy.create_node('grasp_load')
    pub = node.create_publisher(JointState, 'joint_states', qos_profile_sensor_data)
    received = _Received(node, len(names))
    executor = _executor(args.load_executor)
    executor.add_node(node)
    if args.load_priority:  # as ros2_control's controller_manager loop, which sends and takes
        from grasp_torque_opt.ros.realtime import set_fifo

        print(f'load executor thread: {set_fifo(args.load_priority)[1]}', file=sys.stderr)
    pacer = Pacer(executor, args.rate)

    def ready() -> bool:
        return (node.count_subscribers('joint_states') >= 1
                and node.count_publishers(STAMPED_TOPIC) >= 1
                and node.count_publishers('effort_commands') >= 1)

    t_ready = time.perf_counter() + READY_TIMEOUT_S
    while not ready() and time.perf_counter() < t_ready:
        pacer.spin_for(0.05)
    if not ready():
        print('load: nobody answers on joint_states', file=sys.stderr)
        return 1

    window = _Window(args.duration)
    _publish(pacer, pub, setup, received, window)
    pacer.spin_for(DRAIN_S)
    foreign = {'joint_states_publishers': node.count_publishers('joint_states'),
               'joint_states_subscribers': node.count_subscribers('joint_states')}
    node.destroy_node()
    rclpy.try_shutdown()
    if 'start' not in window.times:
        print('load: no command came back', file=sys.stderr)
        return 1
    Path(args.result).write_text(json.dumps(_figures(received, window, foreign)))
    return 0


class _Received:
    """The commands the load process receives: their times, the stamped copies by stamp."""

    def __init__(self, node, m: int) -> None:
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from sensor_msgs.msg import JointState
        from std_msgs.msg import Float64MultiArray

        self.m = m
        self.command_times: list[float] = []  # perf_counter at receipt of each effort_commands
        self.bad_length = 0
        self.stamped: dict[int, int] = {}  # joint-state stamp -> receipt [ns, system clock]
        self.duplicates = 0
        receiver_qos = QoSProfile(depth=RECEIVER_DEPTH, reliability=ReliabilityPolicy.RELIABLE)
        node.create_subscription(Float64MultiArray, 'effort_commands', self.on_command,
                                 receiver_qos)
        node.create_subscription(JointState, STAMPED_TOPIC, self.on_stamped, receiver_qos)

    def on_command(self, msg) -> None:
        self.command_times.append(time.perf_counter())
        if len(msg.data) != self.m:
            self.bad_length += 1

    def on_stamped(self, msg) -> None:
        now = time.time_ns()
        s = stamp_ns(msg.header.stamp)
        if s in self.stamped:
            self.duplicates += 1
        else:
            self.stamped[s] = now


class _Window:
    """The measured window: warm-up from the first command, then ``duration`` [s]."""

    def __init__(self, duration: float) -> None:
        self.duration = duration
        self.times: dict[str, float] = {}  # warm, start, end [perf_counter s]
        self.sent: list[tuple[int, float]] = []  # (stamp [ns], perf_counter at publish)
        self.lateness: list[float] = []  # of the measured ticks [s]
        self.t_start = time.perf_counter()


def _publish(pacer: Pacer, pub, setup, received: _Received, window: _Window) -> None:
    """Publish the joint states on the pacer's deadlines until the window ends."""
    import numpy as np
    from sensor_msgs.msg import JointState

    names = list(setup.hand.joints)
    q0 = setup.q[setup.hand.idx_q].astype(float)
    phase = 0.4 * np.arange(len(names))
    clock = UniqueClock()
    times = window.times

    def tick(k: int, now: float) -> bool:
        if 'warm' not in times:
            if received.stamped:
                times['warm'] = now
                times['start'] = now + WARMUP_S
                times['end'] = times['start'] + window.duration
            elif now - window.t_start > READY_TIMEOUT_S:
                return False
        if 'end' in times and now >= times['end']:
            return False
        msg = JointState(name=names,
                         position=(q0 + AMPLITUDE * np.sin(np.pi * k * pacer.period + phase)
                                   ).tolist())
        s = clock()
        set_stamp(msg.header, s)
        pub.publish(msg)
        if 'start' in times and now >= times['start']:
            window.sent.append((s, now))
            window.lateness.append(pacer.lateness[-1])
        return True

    pacer.run(tick)


def _figures(received: _Received, window: _Window, foreign: dict) -> dict:
    """Return the load process's figures: rates, drops, latency, the graph at the end."""
    sent, stamped = window.sent, received.stamped
    n_pub = len(sent)
    span = sent[-1][1] - sent[0][1] if n_pub > 1 else float('nan')
    latencies = [1e-9 * (stamped[s] - s) for s, _ in sent if s in stamped]
    dropped = n_pub - len(latencies)
    t0, t1 = window.times['start'], window.times['end']
    n_cmd = sum(t0 <= t <= t1 for t in received.command_times)
    return {
        'published': n_pub,
        'publish_rate_hz': (n_pub - 1) / span if n_pub > 1 else None,
        'publish_lateness': percentiles_ms(window.lateness),
        'commands': n_cmd,
        'command_rate_hz': n_cmd / (t1 - t0),
        'answered': len(latencies),
        'dropped': dropped,
        'dropped_pct': 100.0 * dropped / n_pub if n_pub else None,
        'latency': percentiles_ms(latencies),
        'duplicate_stamps': received.duplicates,
        'wrong_length_commands': received.bad_length,
        'time_to_first_command_s': window.times['warm'] - window.t_start,
        'graph_at_end': foreign,
        'dropped_at_s': [round(now - t0, 6) for s, now in sent if s not in stamped],
    }


# -- the run ---------------------------------------------------------------------------------

def run_case(hand: str, target: str, rate: float, executor: str, duration: float,
             load_executor: str, domain: int, tmp: Path, load_priority: int = 0) -> dict:
    """One case: start the answering node, run the load process against it, stop both."""
    from grasp_torque_opt.core.grasp_setup import GraspSetup

    env = isolated_env(domain)
    tag = f"{hand}-{target.replace('/', '-')}-{int(rate)}-{executor}"
    me = [sys.executable, str(Path(__file__).resolve())]
    if target.startswith('echo'):
        joints = GraspSetup.from_file(CONFIG / HANDS[hand][0]).hand.joints
        cmd = me + ['--role', 'echo', '--executor', executor, '--joints', ','.join(joints),
                    '--echo-priority', '50' if target == 'echo/fifo' else '0']
    else:
        extra = ['--log-level', 'error']
        extra += TARGET_ARGS.get(target, [])
        cmd = node_command(CONFIG / HANDS[hand][1], executor, extra)
    result_file = tmp / f'{tag}.json'
    load_cmd = me + ['--role', 'load', '--hand', hand, '--rate', str(rate),
                     '--duration', str(duration), '--load-executor', load_executor,
                     '--load-priority', str(load_priority),
                     '--result', str(result_file)]
    children: list[Child] = []
    with open(tmp / f'{tag}.target.log', 'w') as tlog, open(tmp / f'{tag}.load.log', 'w') as llog:
        try:
            load_before = os.getloadavg()[0]
            share = CpuShare()
            answering = Child(cmd, env, tlog)
            children.append(answering)
            load = Child(load_cmd, env, llog)
            children.append(load)
            timeout = READY_TIMEOUT_S * 2 + duration + 30
            try:
                code = load.proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                code = None
            target_alive = answering.alive()
        finally:
            for c in reversed(children):
                c.stop()
    out = {'hand': hand, 'target': target, 'rate_hz': rate, 'executor': executor,
           'ros_domain_id': domain, 'loadavg_1min_before': load_before,
           'other_processes_cores': share.others_cores(), 'target_alive_at_end': target_alive}
    if code == 0 and result_file.exists():
        out.update(json.loads(result_file.read_text()))
    else:
        tail = ' / '.join(line.strip() for line in
                          (tmp / f'{tag}.load.log').read_text().splitlines()[-3:] if line.strip())
        out['error'] = f'load process exit {code}: {tail} (logs in {tmp})'
    return out


def _fmt(x: float | None, spec: str) -> str:
    return '-' if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def table(cases: list[dict]) -> str:
    """Format the markdown tables: every case, then the node against the echo node."""
    lines = ['| hand | rate [Hz] | executor | answering node | published [Hz] | '
             'commands [Hz] | dropped | dropped [%] | p50 [ms] | p99 [ms] | max [ms] | '
             'other work [cores] |',
             '|---|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|']
    for c in cases:
        if 'error' in c:
            lines.append(f"| {c['hand']} | {c['rate_hz']:g} | {c['executor']} | {c['target']} "
                         f"| failed: {c['error'][:60]} ||||||||")
            continue
        lat = c['latency']
        lines.append(
            f"| {c['hand']} | {c['rate_hz']:g} | {c['executor']} | {c['target']} | "
            f"{_fmt(c['publish_rate_hz'], '.1f')} | {c['command_rate_hz']:.1f} | "
            f"{c['dropped']} | {_fmt(c['dropped_pct'], '.2f')} | "
            f"{_fmt(lat['p50_ms'], '.3f')} | {_fmt(lat['p99_ms'], '.3f')} | "
            f"{_fmt(lat['max_ms'], '.3f')} | {_fmt(c['other_processes_cores'], '.2f')} |")
    lines += ['', '| hand | rate [Hz] | executor | node | p99 node / echo | '
              'dropped node - echo [pp] | p50 node / echo |', '|---|---:|---|---|---:|---:|---:|']
    for r in ratios(cases):
        lines.append(f"| {r['hand']} | {r['rate_hz']:g} | {r['executor']} | {r['target']} | "
                     f"{_fmt(r['p99_ratio'], '.2f')} | {_fmt(r['dropped_diff_pp'], '+.2f')} | "
                     f"{_fmt(r['p50_ratio'], '.2f')} |")
    return '\n'.join(lines)


def ratios(cases: list[dict]) -> list[dict]:
    """Compare the node with the echo node at the same hand, rate and executor."""
    by_key = {(c['hand'], c['rate_hz'], c['executor'], c['target']): c for c in cases}
    out = []
    for (hand, rate, executor, target), node in by_key.items():
        echo = by_key.get((hand, rate, executor, 'echo'))
        if target == 'echo' or echo is None:
            continue
        r = {'hand': hand, 'rate_hz': rate, 'executor': executor, 'target': target,
             'p99_ratio': None,
             'p50_ratio': None, 'dropped_diff_pp': None}
        if 'error' not in node and 'error' not in echo:
            for q in ('p50', 'p99'):
                a, b = node['latency'][f'{q}_ms'], echo['latency'][f'{q}_ms']
                r[f'{q}_ratio'] = a / b if a is not None and b else None
            if node['dropped_pct'] is not None and echo['dropped_pct'] is not None:
                r['dropped_diff_pp'] = node['dropped_pct'] - echo['dropped_pct']
        out.append(r)
    return out


def main_run(args: argparse.Namespace) -> int:
    from cycle import machine

    interrupt_on_signals()
    keys = list(itertools.product(args.hands, args.rates, args.executors, TARGETS))
    domains = private_domains(len(keys))
    m = machine()
    print(f"machine: {m['cpu']}, {m['cores']} cores, Python {m['python']}; {m['date']}")
    print(f'{len(keys)} cases, {args.duration:g} s each after {WARMUP_S:g} s of warm-up; '
          f'load process executor: {args.load_executor}, SCHED_FIFO '
          f"{args.load_priority or 'no'}; receiver depth {RECEIVER_DEPTH}",
          flush=True)
    cases = []
    logs = Path(tempfile.mkdtemp(prefix='node_load_'))
    print(f'logs of the child processes: {logs}')
    for (hand, rate, executor, target), domain in zip(keys, domains):
        c = run_case(hand, target, rate, executor, args.duration, args.load_executor,
                     domain, logs, args.load_priority)
        cases.append(c)
        if 'error' in c:
            print(f"  {hand} {target} {rate:g} Hz {executor}: {c['error']}", flush=True)
        else:
            print(f'  {hand:8} {target:18} {rate:6g} Hz {executor:11} '
                  f"commands {c['command_rate_hz']:7.1f}/s  dropped {c['dropped_pct']:6.2f}%"
                  f"  p50 {_fmt(c['latency']['p50_ms'], '.3f')} ms"
                  f"  p99 {_fmt(c['latency']['p99_ms'], '.3f')} ms"
                  f"  (other work: {_fmt(c['other_processes_cores'], '.2f')} cores)",
                  flush=True)
    print()
    print(table(cases))
    out = {'machine': m, 'date_utc': datetime.now(timezone.utc).isoformat(timespec='seconds'),
           'duration_s': args.duration, 'warmup_s': WARMUP_S, 'drain_s': DRAIN_S,
           'load_executor': args.load_executor, 'load_priority': args.load_priority,
           'receiver_depth': RECEIVER_DEPTH,
           'cases': cases, 'node_vs_echo': ratios(cases)}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(out, indent=2))
    print(f'\nwritten: {args.out}')
    return 0 if all('error' not in c for c in cases) else 1


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--duration', type=float, default=10.0,
                        help='measured seconds per case [s]')
    parser.add_argument('--rates', type=float, nargs='+', default=[500.0, 1000.0],
                        help='joint-state rates [Hz]')
    parser.add_argument('--hands', nargs='+', choices=sorted(HANDS), default=list(HANDS))
    parser.add_argument('--executors', nargs='+', choices=EXECUTORS, default=list(EXECUTORS),
                        help='executors of the answering nodes')
    parser.add_argument('--load-executor', choices=['single', 'events'], default='events',
                        help='executor of the load process itself (the same in every case)')
    parser.add_argument('--load-priority', type=int, default=0,
                        help='SCHED_FIFO priority of the load process (0: normal); 50 sends and '
                             "takes as ros2_control's controller_manager loop would")
    parser.add_argument('--out', type=Path,
                        default=Path(__file__).resolve().parent / 'results' / 'node_load.json')
    # Roles of the child processes.
    parser.add_argument('--role', choices=['run', 'echo', 'load'], default='run',
                        help=argparse.SUPPRESS)
    parser.add_argument('--executor', choices=EXECUTORS, default='single',
                        help=argparse.SUPPRESS)
    parser.add_argument('--joints', help=argparse.SUPPRESS)
    parser.add_argument('--echo-qos', choices=['sensor', 'node'], default='sensor',
                        help=argparse.SUPPRESS)
    parser.add_argument('--echo-priority', type=int, default=0, help=argparse.SUPPRESS)
    parser.add_argument('--hand', choices=sorted(HANDS), help=argparse.SUPPRESS)
    parser.add_argument('--rate', type=float, help=argparse.SUPPRESS)
    parser.add_argument('--result', help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.role == 'echo':
        return echo_main(args)
    if args.role == 'load':
        return load_main(args)
    try:
        return main_run(args)
    except KeyboardInterrupt:
        print('node_load: interrupted, child processes stopped', file=sys.stderr)
        return 130


if __name__ == '__main__':
    sys.exit(main())
