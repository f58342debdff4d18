# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The node under test beside a tester node, on a ROS domain of this test run's own."""

import os
from pathlib import Path
import time

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Pose, PoseArray, WrenchStamped
from grasp_torque_opt.ros.node import COMMAND_QOS, GraspTorqueNode, SERVICE_QOS
import numpy as np
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray
from std_srvs.srv import Trigger
from visualization_msgs.msg import MarkerArray

# Each run on its own domain, heard only on this machine.
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
DOMAIN = 1 + os.getpid() % 100


class Harness:
    """The node under test and a tester node on one executor."""

    def __init__(self, scenario: Path, **params):
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=DOMAIN)
        # The most generous cycle budget unless a test is about it: other processes may
        # load this machine, and an overrun drops the command by design.
        params.setdefault('cycle_budget', 1.0)
        # Diagnostics at 10 Hz (the node's default is 1 Hz), so tests need not wait seconds.
        params.setdefault('diagnostics_period', 0.1)
        overrides = [Parameter('scenario', value=str(scenario))]
        overrides += [Parameter(k.replace('__', '.'), value=v) for k, v in params.items()]
        self.node = GraspTorqueNode(context=self.context, parameter_overrides=overrides)
        self.tester = rclpy.create_node('tester', context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.executor.add_node(self.tester)
        t = self.tester
        self.js_pub = t.create_publisher(JointState, 'joint_states', qos_profile_sensor_data)
        self.contacts_pub = t.create_publisher(PoseArray, 'contacts', qos_profile_sensor_data)
        self.wrench_pub = t.create_publisher(WrenchStamped, 'external_wrench',
                                             qos_profile_sensor_data)
        self.commands: list[tuple[float, np.ndarray]] = []
        self.diagnostics: list[dict] = []
        self.markers: list[MarkerArray] = []
        t.create_subscription(Float64MultiArray, 'effort_commands',
                              lambda m: self.commands.append((time.monotonic(),
                                                              np.array(m.data))), COMMAND_QOS)
        t.create_subscription(DiagnosticArray, '/diagnostics', self._on_diag, 10)
        t.create_subscription(MarkerArray, 'grasp_torque_node/contact_wrenches',
                              self.markers.append, 1)
        self.solve_client = t.create_client(Trigger, 'grasp_torque_node/solve',
                                            qos_profile=SERVICE_QOS)
        assert self.spin_until(lambda: self.js_pub.get_subscription_count() > 0
                               and self.contacts_pub.get_subscription_count() > 0
                               and self.solve_client.service_is_ready(), 10.0)

    def _on_diag(self, msg):
        for s in msg.status:
            if s.name.startswith('grasp_torque_node'):
                self.diagnostics.append({**{kv.key: kv.value for kv in s.values},
                                         '_level': s.level[0], '_message': s.message,
                                         '_hardware_id': s.hardware_id})

    def spin_until(self, predicate, timeout: float) -> bool:
        end = time.monotonic() + timeout
        while not predicate() and time.monotonic() < end:
            self.executor.spin_once(timeout_sec=0.005)
        return predicate()

    def spin_for(self, seconds: float) -> None:
        self.spin_until(lambda: False, seconds)

    def send_joint_state(self, names, positions) -> None:
        self.js_pub.publish(JointState(name=list(names), position=[float(x) for x in positions],
                                       effort=[float('nan')] * len(names)))

    def next_command(self, timeout: float = 2.0) -> np.ndarray | None:
        n = len(self.commands)
        self.spin_until(lambda: len(self.commands) > n, timeout)
        return self.commands[-1][1] if len(self.commands) > n else None

    def send_contacts(self, frame, positions, quaternions) -> None:
        msg = PoseArray()
        msg.header.frame_id = frame
        for p, q in zip(positions, quaternions):
            pose = Pose()
            pose.position.x, pose.position.y, pose.position.z = (float(v) for v in p)
            (pose.orientation.x, pose.orientation.y, pose.orientation.z,
             pose.orientation.w) = (float(v) for v in q)
            msg.poses.append(pose)
        self.contacts_pub.publish(msg)

    def close(self) -> None:
        self.node.destroy_node()
        self.tester.destroy_node()
        self.executor.shutdown()
        rclpy.try_shutdown(context=self.context)
