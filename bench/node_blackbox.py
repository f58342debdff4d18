# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The node measured as a user measures it: joint states in, effort commands counted, from outside.

Usage: .venv/bin/python bench/node_blackbox.py [--duration 8] [--rates 500 1000] [--runs 1]
       [--targets TARGET ...]

Each case starts one answering process exactly as a user would, with nothing
added: ``grasp_torque_node --ros-args --params-file config/allegro_right_node.yaml``
(the default executor, the node's own wait-set loop; the default backend, DAQP
with its verified warm start, in the compiled cycle; normal scheduling), then with ``-p
thread_priority:=50`` (the spinning thread SCHED_FIFO 50, as ros2_control's
controller_manager asks for its loop), with ``-p solver.compiled:=false``
(the Python cycle, the default before the compiled one), with that and
``-p solver.warm_start:=false`` as well (the cold ProxSuite default before the
warm start), with ``-p solver.backend:=proxsuite -p solver.fallback:=daqp`` (the
default before DAQP's compiled cycle), with ``-p object_loop.enabled:=false``
(the params file's object loop off: its share of the cost), and the trivial
echo node of ``bench/node_load.py`` (one zero command per joint state), taking
joint states with sensor-data QoS (keep last 5) and, as ``echo, joint_states depth
1``, with the node's own QoS (keep last 1), and as ``echo, SCHED_FIFO 50`` with the
thread priority the node asks; and the node with ``--executor events``
(rclpy's experimental events executor, its main's flag, not a parameter), with
``--executor single`` (rclpy's SingleThreadedExecutor, the default before issue 36)
and ``--executor waitset`` (the default, named). A
separate process publishes Allegro joint states at the rate with sensor-data
QoS for ``--duration`` seconds once the answering node is discovered and has
answered once, and counts the ``effort_commands`` that arrive (a plain
subscriber, reliable, depth 10, as ``ros2 topic hz`` would see them) until 0.5 s
after its last joint state. "answered" is commands over joint states published;
"CPU per joint state" is the answering process's CPU time (user and system, all
its threads, from /proc) over the published window divided by the joint states:
the headroom a rate leaves on this machine.

This differs from ``node_load.py`` on purpose: no stamped second topic (the node
publishes only what a user's controller reads), no warm-up excluded, no stamp
matching; it gives no latency. Speed is measured here, never asserted.
"""

from __future__ import annotations

import argparse
from datetime import datetime, timezone
import json
from pathlib import Path
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
    Pacer,
    private_domains,
    process_cpu_s,
)

PARAMS = CONFIG / 'allegro_right_node.yaml'
SCENARIO = CONFIG / 'allegro_right.yaml'
#: Answering processes: name -> extra node arguments (None: the echo node).
TARGETS = {'echo': None, 'echo, joint_states depth 1': None, 'echo, SCHED_FIFO 50': None,
           'grasp_torque_node (default)': [],
           'grasp_torque_node thread_priority:=50': ['-p', 'thread_priority:=50'],
           'grasp_torque_node --executor events': ['--executor', 'events'],
           'grasp_torque_node --executor single': ['--executor', 'single'],
           'grasp_torque_node --executor waitset': ['--executor', 'waitset'],
           'grasp_torque_node compiled:=false': ['-p', 'solver.compiled:=false'],
           'grasp_torque_node warm_start:=false compiled:=false':
               ['-p', 'solver.warm_start:=false', '-p', 'solver.compiled:=false'],
           'grasp_torque_node backend:=proxsuite':
               ['-p', 'solver.backend:=proxsuite', '-p', 'solver.fallback:=daqp'],
           'grasp_torque_node object_loop:=false': ['-p', 'object_loop.enabled:=false']}
DRAIN_S = 0.5
READY_TIMEOUT_S = 15.0


def count_main(args: argparse.Namespace) -> int:
    """Run the user's process: publish joint states, count the commands, write JSON."""
    from grasp_torque_opt.core.grasp_setup import GraspSetup
    import numpy as np
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import JointState
    from std_msgs.msg import Float64MultiArray

    setup = GraspSetup.from_file(SCENARIO)
    names = list(setup.hand.joints)
    q0 = setup.q[setup.hand.idx_q].astype(float)
    rclpy.init(args=[sys.argv[0]])
    node = rclpy.create_node('blackbox_user')
    pub = node.create_publisher(JointState, 'joint_states', qos_profile_sensor_data)
    received = []
    node.create_subscription(Float64MultiArray, 'effort_commands',
                             lambda m: received.append(len(m.data)), 10)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    pacer = Pacer(executor, args.rate)

    def state(k: int) -> JointState:
        msg = JointState(name=names, position=(q0 + 1e-3 * np.sin(
            np.pi * k * pacer.period + 0.4 * np.arange(len(names)))).tolist())
        msg.header.stamp = node.get_clock().now().to_msg()
        return msg

    end = time.monotonic() + READY_TIMEOUT_S
    k = 0
    while not received and time.monotonic() < end:  # discovered and answering once
        pub.publish(state(k))
        k += 1
        pacer.spin_for(0.01)
    if not received:
        print('user: no effort command came back', file=sys.stderr)
        return 1
    pacer.spin_for(0.2)
    received.clear()
    published = 0

    def tick(k: int, now: float) -> bool:
        nonlocal published
        if published >= int(args.duration * args.rate):
            return False
        pub.publish(state(k))
        published += 1
        return True

    cpu0 = process_cpu_s(args.target_pid)
    pacer.run(tick)
    cpu1 = process_cpu_s(args.target_pid)
    pacer.spin_for(DRAIN_S)
    node.destroy_node()
    rclpy.try_shutdown()
    Path(args.result).write_text(json.dumps({
        'published': published, 'commands': len(received),
        'wrong_length': sum(n != len(names) for n in received),
        'target_cpu_s': None if cpu0 is None or cpu1 is None else cpu1 - cpu0}))
    return 0


def run_case(target: str, rate: float, duration: float, domain: int, tmp: Path) -> dict:
    env = isolated_env(domain)
    extra = TARGETS[target]
    bench = Path(__file__).resolve().parent
    if extra is None:
        from grasp_torque_opt.core.grasp_setup import GraspSetup

        joints = GraspSetup.from_file(SCENARIO).hand.joints
        cmd = [sys.executable, str(bench / 'node_load.py'), '--role', 'echo',
               '--executor', 'single', '--joints', ','.join(joints),
               '--echo-qos', 'node' if 'depth 1' in target else 'sensor',
               '--echo-priority', '50' if 'FIFO' in target else '0']
    else:
        exe = Path(sys.executable).parent / 'grasp_torque_node'
        pre = extra[:2] if extra[:1] == ['--executor'] else []  # the node's own flag
        cmd = [str(exe), *pre, '--ros-args', '--params-file', str(PARAMS)] + extra[len(pre):]
    tag = f'{target}-{rate:g}'
    tag = ''.join(c if c.isalnum() or c in '-.' else '_' for c in tag)
    result = tmp / f'{tag}.json'
    user = [sys.executable, str(Path(__file__).resolve()), '--role', 'user', '--rate',
            str(rate), '--duration', str(duration), '--result', str(result)]
    share = CpuShare()
    with open(tmp / f'{tag}.target.log', 'w') as tlog, open(tmp / f'{tag}.user.log', 'w') as ulog:
        answering = Child(cmd, env, tlog)
        counter = Child(user + ['--target-pid', str(answering.pid)], env, ulog)
        try:
            code = counter.proc.wait(timeout=READY_TIMEOUT_S + duration + 30)
        finally:
            counter.stop()
            answering.stop()
    out = {'target': target, 'rate_hz': rate, 'other_processes_cores': share.others_cores()}
    if code == 0 and result.exists():
        r = json.loads(result.read_text())
        out.update(r, answered_pct=100.0 * r['commands'] / r['published'])
        cpu = r.get('target_cpu_s')
        out['target_cpu_per_state_us'] = (None if cpu is None or not r['published']
                                          else 1e6 * cpu / r['published'])
    else:
        out['error'] = f'user process exit {code} (logs in {tmp})'
    return out


def table(cases: list[dict]) -> str:
    lines = ['| rate [Hz] | answering process | run | joint states | commands | answered [%] '
             '| CPU per joint state [us] | other work [cores] |',
             '|---:|---|---:|---:|---:|---:|---:|---:|']
    for c in cases:
        if 'error' in c:
            lines.append(f"| {c['rate_hz']:g} | {c['target']} | {c['run']} | failed: "
                         f"{c['error']} |||||")
            continue
        other, cpu = c['other_processes_cores'], c.get('target_cpu_per_state_us')
        lines.append(f"| {c['rate_hz']:g} | {c['target']} | {c['run']} | {c['published']} | "
                     f"{c['commands']} | {c['answered_pct']:.1f} | "
                     f"{'-' if cpu is None else f'{cpu:.0f}'} | "
                     f"{'-' if other is None else f'{other:.2f}'} |")
    return '\n'.join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--duration', type=float, default=8.0, help='seconds published [s]')
    parser.add_argument('--rates', type=float, nargs='+', default=[500.0, 1000.0])
    parser.add_argument('--runs', type=int, default=1, help='runs of every case')
    parser.add_argument('--targets', nargs='+', choices=list(TARGETS), default=list(TARGETS),
                        metavar='TARGET', help='answering processes (default: all of: '
                        + '; '.join(TARGETS) + ')')
    parser.add_argument('--out', type=Path,
                        default=Path(__file__).resolve().parent / 'results' / 'node_blackbox.json')
    parser.add_argument('--role', choices=['run', 'user'], default='run', help=argparse.SUPPRESS)
    parser.add_argument('--rate', type=float, help=argparse.SUPPRESS)
    parser.add_argument('--result', help=argparse.SUPPRESS)
    parser.add_argument('--target-pid', type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.role == 'user':
        return count_main(args)
    from cycle import machine

    interrupt_on_signals()
    m = machine()
    print(f"machine: {m['cpu']}, {m['cores']} cores, Python {m['python']}; {m['date']}",
          flush=True)
    keys = [(rate, target, run) for run in range(1, args.runs + 1) for rate in args.rates
            for target in args.targets]
    tmp = Path(tempfile.mkdtemp(prefix='node_blackbox_'))
    cases = []
    for (rate, target, run), domain in zip(keys, private_domains(len(keys))):
        c = run_case(target, rate, args.duration, domain, tmp)
        c['run'] = run
        cases.append(c)
        line = c.get('error') or (
            f"answered {c['answered_pct']:5.1f}% ({c['commands']} of {c['published']}), "
            f"CPU per joint state {c.get('target_cpu_per_state_us') or 0:.0f} us")
        print(f'  {rate:6g} Hz  {target:38} {line}', flush=True)
    print()
    print(table(cases))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({'machine': m, 'date_utc': datetime.now(timezone.utc)
                                    .isoformat(timespec='seconds'), 'duration_s': args.duration,
                                    'cases': cases}, indent=2))
    print(f'\nwritten: {args.out}')
    return 0 if all('error' not in c for c in cases) else 1


if __name__ == '__main__':
    sys.exit(main())
