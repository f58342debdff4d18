# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The node's memory under oversized joint states, with Fast DDS's reader memory policies.

Usage: .venv/bin/python bench/oversized.py [--sizes 50 50 50 100] [--repeats 3]
       [--reader-policy default|DYNAMIC|DYNAMIC_REUSABLE]

``grasp_torque_node`` runs as a child on ``config/allegro_right_node.yaml`` (a private
domain, localhost only); this process publishes, for each size in ``--sizes`` [MiB],
``--repeats`` joint states of that many float64 positions from two publishers (best
effort and reliable, as two misbehaving sources would), and prints the child's VmRSS
after each size. The node refuses every one by its serialized length
(``max_message_bytes``); the memory is Fast DDS's reassembly of the samples.
``--reader-policy`` other than ``default`` runs the child with a Fast DDS XML profile
giving its readers that ``historyMemoryPolicy`` (``RMW_FASTRTPS_USE_QOS_FROM_XML=1``).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import subprocess
import sys
import tempfile
import time

from cycle import machine, machine_line
from grasp_torque_opt.ros.domains import private
import numpy as np
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import qos_profile_sensor_data, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState

ROOT = Path(__file__).resolve().parent.parent
PROFILE = """<?xml version="1.0" encoding="UTF-8" ?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <profiles>
    <data_writer profile_name="writers" is_default_profile="true">
      <historyMemoryPolicy>PREALLOCATED_WITH_REALLOC</historyMemoryPolicy>
    </data_writer>
    <data_reader profile_name="readers" is_default_profile="true">
      <historyMemoryPolicy>{policy}</historyMemoryPolicy>
    </data_reader>
  </profiles>
</dds>
"""


def rss_mib(pid: int) -> float:
    """Give a process's resident memory [MiB]."""
    for line in Path(f'/proc/{pid}/status').read_text().splitlines():
        if line.startswith('VmRSS:'):
            return int(line.split()[1]) / 1024.0
    raise RuntimeError('no VmRSS')


def run(sizes: list[float], repeats: int, policy: str, domain: int) -> list[tuple[str, float]]:
    """Run the node as a child and return (what was sent, its VmRSS [MiB]) rows."""
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    with tempfile.TemporaryDirectory() as tmp:
        if policy != 'default':
            xml = Path(tmp) / 'profile.xml'
            xml.write_text(PROFILE.format(policy=policy))
            env.update(RMW_FASTRTPS_USE_QOS_FROM_XML='1', FASTRTPS_DEFAULT_PROFILES_FILE=str(xml))
        child = subprocess.Popen(
            [sys.executable, '-m', 'grasp_torque_opt.ros.node', '--ros-args', '--params-file',
             str(ROOT / 'config' / 'allegro_right_node.yaml'), '--log-level', 'error'], env=env)
        context = rclpy.Context()
        rclpy.init(context=context, domain_id=domain)
        node = rclpy.create_node('oversized_bench', context=context)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        pubs = [node.create_publisher(JointState, 'joint_states', qos_profile_sensor_data),
                node.create_publisher(JointState, 'joint_states',
                                      QoSProfile(depth=10,
                                                 reliability=ReliabilityPolicy.RELIABLE))]

        def spin(seconds: float) -> None:
            end = time.monotonic() + seconds
            while time.monotonic() < end:
                executor.spin_once(timeout_sec=0.01)
        try:
            spin(6.0)  # the child starts and matches
            rows = [('start', rss_mib(child.pid))]
            for size in sizes:
                msg = JointState(name=['x'],
                                 position=np.zeros(int(size * 1024 * 1024) // 8).tolist())
                for _ in range(repeats):
                    for pub in pubs:
                        pub.publish(msg)
                    spin(0.5)
                spin(2.0)
                rows.append((f'{repeats} x {size:g} MiB x {len(pubs)} publishers',
                             rss_mib(child.pid)))
            return rows
        finally:
            child.terminate()
            child.wait(10)
            node.destroy_node()
            executor.shutdown()
            rclpy.try_shutdown(context=context)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    ap.add_argument('--sizes', type=float, nargs='+', default=[50.0, 50.0, 50.0, 100.0])
    ap.add_argument('--repeats', type=int, default=3)
    ap.add_argument('--reader-policy', default='default',
                    choices=['default', 'DYNAMIC', 'DYNAMIC_REUSABLE'])
    ap.add_argument('--domain', type=int, default=None,
                    help='the ROS domain of the node and this process (default: '
                         'ROS_DOMAIN_ID + 1, by grasp_torque_opt.ros.domains)')
    a = ap.parse_args()
    print(machine_line(machine()))
    print(f'reader history memory policy: {a.reader_policy}')
    domain = private(0) if a.domain is None else a.domain
    for what, rss in run(a.sizes, a.repeats, a.reader_policy, domain):
        print(f'{what:40s} node VmRSS {rss:8.1f} MiB')


if __name__ == '__main__':
    main()
