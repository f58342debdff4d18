# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""grasp-torque-demo --watch: follows a remapped node, publishes nothing, ends when told."""

import os
from pathlib import Path
import signal
import subprocess
import sys
import time

import rclpy
from rclpy.executors import SingleThreadedExecutor
from ros_harness import DOMAIN
from std_msgs.msg import Float64MultiArray

DEMO = str(Path(sys.executable).parent / 'grasp-torque-demo')
ENV = {**os.environ, 'ROS_DOMAIN_ID': str(DOMAIN), 'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST'}
#: What the demo publishes when it plays a hand; a watch publishes none of it.
PLAYED = {'/joint_states', '/contacts', '/external_wrench'}


class FakeNode:
    """A node that publishes 16 small torques on a topic, as a remapped grasp_torque_node."""

    def __init__(self, topic: str, name: str = 'grasp_torque_node', namespace: str = '/'):
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=DOMAIN)
        self.node = rclpy.create_node(name, namespace=namespace, context=self.context)
        self.pub = self.node.create_publisher(Float64MultiArray, topic, 1)
        self.node.create_timer(0.02, lambda: self.pub.publish(Float64MultiArray(
            data=[0.01] * 16)))
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)

    def spin_while(self, proc: subprocess.Popen, timeout: float = 60.0) -> set[str]:
        """Spin until the process ends; return every topic the demo's node published on."""
        seen: set[str] = set()
        end = time.monotonic() + timeout
        while proc.poll() is None and time.monotonic() < end:
            self.executor.spin_once(timeout_sec=0.05)
            try:
                seen.update(t for t, _ in self.node.get_publisher_names_and_types_by_node(
                    'grasp_demo_driver', '/'))
            except Exception:  # noqa: B902 -- not on the graph yet, or gone
                pass
        return seen

    def close(self):
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


def watch(*args):
    return subprocess.Popen([DEMO, '--watch', *args], env=ENV, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def test_the_watch_follows_a_remapped_node_and_publishes_nothing():
    fake = FakeNode('/effort_controller/commands')
    try:
        proc = watch('--duration', '3', '--ros-args', '-r',
                     'effort_commands:=/effort_controller/commands')
        published = fake.spin_while(proc)
        out, err = proc.communicate(timeout=30)
    finally:
        fake.close()
    assert proc.returncode == 0, err
    assert 'watching /effort_controller/commands' in out
    summary = next(line for line in out.splitlines() if line.startswith('summary:'))
    assert not summary.startswith('summary: 0 commands'), out
    assert '|command| 0.0400' in out  # ||[0.01] * 16|| = 0.04
    assert published and not published & PLAYED, published


def test_the_watch_follows_a_node_by_name():
    fake = FakeNode('/right_hand/effort_controller/commands', namespace='/right_hand')
    try:
        proc = watch('--duration', '4', '--node', '/right_hand/grasp_torque_node')
        fake.spin_while(proc)
        out, err = proc.communicate(timeout=30)
    finally:
        fake.close()
    assert proc.returncode == 0, err
    assert 'watching /right_hand/effort_controller/commands' in out
    assert '|command| 0.0400' in out


def test_without_a_node_the_watch_ends_after_its_duration():
    t0 = time.monotonic()
    done = subprocess.run([DEMO, '--watch', '--duration', '1'], env=ENV, capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert time.monotonic() - t0 < 20  # it waited 30 s for a node before
    assert 'summary: 0 commands' in done.stdout


def test_ctrl_c_ends_the_watch_quietly():
    proc = watch('--duration', '60')
    line = proc.stdout.readline()  # it is watching
    assert line.startswith('grasp-torque-demo: watching'), line
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    assert 'Traceback' not in err, err
    assert proc.returncode in (0, 130)
