# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The control loop under ``~/solve`` floods: the command rate while a client bursts calls.

Usage: .venv/bin/python bench/solve_flood.py [--rate 1000] [--duration 12]
       [--bursts 3] [--calls 1000] [--out FILE]

``grasp_torque_node`` runs as a child on ``config/allegro_right_node.yaml`` (a private
domain, localhost only), as a user starts it. This process publishes the grasp's joint
states at ``--rate`` on absolute deadlines and counts the effort commands that come
back; ``--bursts`` times, evenly spread, a keep-all client sends ``--calls``
concurrent ``~/solve`` requests (the outside attack of issue 27: three bursts of 1,000
took the command rate from about 900 Hz to 69-190 Hz with gaps of 68-175 ms). It
prints, for the quiet seconds and for the 2 s after each burst's start: the command
rate, the longest gap between two commands, and how the calls were answered (solved,
busy, cannot solve, unanswered). Speed is measured here, never asserted.
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
import subprocess
import sys
import time

from cycle import machine, machine_line
from grasp_torque_opt.ros.domains import private
import numpy as np
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import HistoryPolicy, qos_profile_sensor_data, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray
from std_srvs.srv import Trigger

ROOT = Path(__file__).resolve().parent.parent
WINDOW_S = 2.0


def grasp_joint_state() -> tuple[list[str], list[float]]:
    """Return the bundled Allegro grasp's joint names and positions."""
    import yaml

    doc = yaml.safe_load((ROOT / 'config' / 'allegro_right.yaml').read_text())
    q = doc['grasp']['joint_positions']
    return list(q), [float(v) for v in q.values()]


def run(rate: float, duration: float, bursts: int, calls: int, domain: int) -> dict:
    """Run the node as a child under the floods; return the figures."""
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    child = subprocess.Popen(
        [sys.executable, '-m', 'grasp_torque_opt.ros.node', '--ros-args', '--params-file',
         str(ROOT / 'config' / 'allegro_right_node.yaml'), '--log-level', 'error'], env=env)
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain)
    node = rclpy.create_node('solve_flood_bench', context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    arrivals: list[float] = []
    node.create_subscription(Float64MultiArray, 'effort_commands',
                             lambda _: arrivals.append(time.monotonic()),
                             QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE))
    pub = node.create_publisher(JointState, 'joint_states', qos_profile_sensor_data)
    client = node.create_client(Trigger, 'grasp_torque_node/solve', qos_profile=QoSProfile(
        history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE))
    names, pos = grasp_joint_state()
    futures: list[list] = []
    try:
        end = time.monotonic() + 30.0
        while not arrivals and time.monotonic() < end:  # discovery and the first command
            pub.publish(JointState(name=names, position=pos))
            executor.spin_once(timeout_sec=0.01)
        if not arrivals:
            raise RuntimeError('no command from grasp_torque_node within 30 s')
        period = 1.0 / rate
        t0 = time.monotonic() + 1.0
        starts = [t0 + (k + 1) * duration / (bursts + 1) for k in range(bursts)]
        next_pub, k_burst = time.monotonic(), 0
        arrivals.clear()
        while (now := time.monotonic()) < t0 + duration:
            if now >= next_pub:
                msg = JointState(name=names, position=pos)
                msg.header.stamp = node.get_clock().now().to_msg()
                pub.publish(msg)
                next_pub += period
            if k_burst < bursts and now >= starts[k_burst]:
                futures.append([client.call_async(Trigger.Request()) for _ in range(calls)])
                k_burst += 1
            executor.spin_once(timeout_sec=max(0.0, next_pub - time.monotonic()))
        drain = time.monotonic() + 10.0
        while time.monotonic() < drain and not all(f.done() for b in futures for f in b):
            executor.spin_once(timeout_sec=0.01)
    finally:
        child.terminate()
        child.wait(10)
    a = np.array([t for t in arrivals if t >= t0])
    out = {'rate_hz': rate, 'calls': calls, 'bursts': []}

    def window(lo: float, hi: float) -> dict:
        w = a[(a >= lo) & (a < hi)]
        gap = float(np.diff(w).max()) if w.size > 1 else float('inf')
        return {'rate_hz': w.size / (hi - lo), 'max_gap_ms': 1e3 * gap}
    quiet = [(t0, starts[0])] if starts else [(t0, t0 + duration)]
    out['quiet'] = window(*quiet[0])
    for s, batch in zip(starts, futures):
        answers = [f.result() for f in batch if f.done()]
        out['bursts'].append({**window(s, s + WINDOW_S), 'answered': {
            'solved': sum(x.success for x in answers),
            'busy': sum(x.message.startswith('busy: ') for x in answers),
            'cannot solve': sum(not x.success and not x.message.startswith('busy: ')
                                for x in answers),
            'unanswered': len(batch) - len(answers)}})
    node.destroy_node()
    executor.shutdown()
    rclpy.try_shutdown(context=context)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    ap.add_argument('--rate', type=float, default=1000.0)
    ap.add_argument('--duration', type=float, default=12.0)
    ap.add_argument('--bursts', type=int, default=3)
    ap.add_argument('--calls', type=int, default=1000)
    ap.add_argument('--domain', type=int, default=None,
                    help='the ROS domain of the node and this process (default: '
                         'ROS_DOMAIN_ID + 1, by grasp_torque_opt.ros.domains)')
    ap.add_argument('--out', type=Path)
    a = ap.parse_args()
    m = machine()
    r = run(a.rate, a.duration, a.bursts, a.calls, private(0) if a.domain is None else a.domain)
    print(machine_line(m))
    q = r['quiet']
    print(f"before the bursts: commands {q['rate_hz']:.0f} Hz, longest gap "
          f"{q['max_gap_ms']:.1f} ms (joint states at {a.rate:g} Hz)")
    for k, b in enumerate(r['bursts']):
        ans = ', '.join(f'{n} {v}' for n, v in b['answered'].items())
        print(f'burst {k + 1} of {a.calls} calls, first {WINDOW_S:g} s: commands '
              f"{b['rate_hz']:.0f} Hz, longest gap {b['max_gap_ms']:.1f} ms; {ans}")
    if a.out:
        a.out.write_text(json.dumps({'machine': m, **r}, indent=1))


if __name__ == '__main__':
    main()
