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
import subprocess
import sys
import time

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Pose, PoseArray, Vector3Stamped, WrenchStamped
from grasp_torque_opt.ros.lifecycle_node import GraspTorqueLifecycleNode
from grasp_torque_opt.ros.node import COMMAND_QOS, GraspTorqueNode, SERVICE_QOS
from grasp_torque_opt.ros.node.waitset import WaitSetExecutor
from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState, GetState
import numpy as np
from rcl_interfaces.msg import Log
from rcl_interfaces.srv import SetParameters
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_sensor_data
from ros_domains import domain
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray
from std_srvs.srv import Trigger
from visualization_msgs.msg import MarkerArray

# Each run on its own domains above ROS_DOMAIN_ID (ros_domains.py), heard only on this
# machine.
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
DOMAIN = domain('in_process')
#: The domain of the node processes this run starts (NodeProcess, the simulated hand):
#: not this process's own, where its in-process nodes named grasp_torque_node live, so
#: that a child's start-up check never takes one of those for a namesake.
PROCESS_DOMAIN = domain('process')


class Harness:
    """The node under test and a tester node on one executor."""

    def __init__(self, scenario: Path | None, **params):
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=DOMAIN)
        # The most generous cycle budget unless a test is about it: other processes may
        # load this machine, and an overrun drops the command by design.
        params.setdefault('cycle_budget', 1.0)
        # The rate rule off unless a test is about it: tests compare each command with the
        # certified solution of its state.
        params.setdefault('max_torque_rate', 1e6)  # N m/s: 1 kN m a millisecond
        # Diagnostics at 10 Hz (the node's default is 1 Hz), so tests need not wait seconds.
        params.setdefault('diagnostics_period', 0.1)
        overrides = [] if scenario is None else [Parameter('scenario', value=str(scenario))]
        overrides += [Parameter(k.replace('__', '.'), value=v) for k, v in params.items()]
        self.node = self.make_node(overrides)
        self.tester = rclpy.create_node('tester', context=self.context)
        # The executor the node's main spins by default (the node's own wait-set loop).
        self.executor = WaitSetExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.executor.add_node(self.tester)
        t = self.tester
        self.js_pub = t.create_publisher(JointState, 'joint_states', qos_profile_sensor_data)
        self.contacts_pub = t.create_publisher(PoseArray, 'contacts', qos_profile_sensor_data)
        self.wrench_pub = t.create_publisher(WrenchStamped, 'external_wrench',
                                             qos_profile_sensor_data)
        self.gravity_pub = t.create_publisher(Vector3Stamped, 'gravity',
                                              qos_profile_sensor_data)
        self.commands: list[tuple[float, np.ndarray]] = []
        self.diagnostics: list[dict] = []
        self.markers: list[MarkerArray] = []
        self.logs: list[Log] = []
        t.create_subscription(Float64MultiArray, 'effort_commands',
                              lambda m: self.commands.append((time.monotonic(),
                                                              np.array(m.data))), COMMAND_QOS)
        t.create_subscription(DiagnosticArray, '/diagnostics', self._on_diag, 10)
        t.create_subscription(MarkerArray, 'grasp_torque_node/contact_wrenches',
                              self.markers.append, 1)
        self.log_sub = t.create_subscription(Log, '/rosout', self._on_log, 100)
        self.solve_client = t.create_client(Trigger, 'grasp_torque_node/solve',
                                            qos_profile=SERVICE_QOS)
        assert self.spin_until(self.ready, 10.0)
        # /rosout matched to the node's and the tester's own publishers: a warning logged at
        # once (a test's first bad message) reaches self.logs.
        assert self.spin_until(lambda: self.log_sub.get_publisher_count() >= 2, 10.0)
        # An earlier test's node of this name may linger in the graph a moment after it
        # was destroyed: the node would report it (an ERROR on /diagnostics) as a namesake.
        assert self.spin_until(lambda: self.namesakes() == 0, 10.0), \
            'an earlier node named grasp_torque_node stayed on this domain for 10 s'
        self.diagnostics = [d for d in self.diagnostics if d.get('duplicate_nodes') == '0']

    def namesakes(self) -> int:
        """Count the other nodes named grasp_torque_node the tester sees."""
        me = ('grasp_torque_node', '/')
        return sum(1 for n in self.tester.get_node_names_and_namespaces() if tuple(n) == me) - 1

    def make_node(self, overrides):
        return GraspTorqueNode(context=self.context, parameter_overrides=overrides)

    def ready(self) -> bool:
        return (self.js_pub.get_subscription_count() > 0
                and self.contacts_pub.get_subscription_count() > 0
                and self.solve_client.service_is_ready())

    def _on_diag(self, msg):
        for s in msg.status:
            if s.name.startswith('/grasp_torque_node: '):
                self.diagnostics.append({**{kv.key: kv.value for kv in s.values},
                                         '_level': s.level[0], '_message': s.message,
                                         '_hardware_id': s.hardware_id})

    def _on_log(self, msg):
        if msg.name == self.node.get_logger().name:
            self.logs.append(msg)

    def spin_until(self, predicate, timeout: float) -> bool:
        end = time.monotonic() + timeout
        while not predicate() and time.monotonic() < end:
            self.executor.spin_once(timeout_sec=0.005)
        return predicate()

    def spin_for(self, seconds: float) -> None:
        self.spin_until(lambda: False, seconds)

    def call(self, client, request, timeout: float = 10.0):
        """Call a service of the node from the tester and wait for the answer."""
        assert self.spin_until(client.service_is_ready, timeout)
        future = client.call_async(request)
        assert self.spin_until(future.done, timeout), f'no answer from {client.srv_name}'
        return future.result()

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

    def assert_contacts_refused(self, why, names, positions, expected, atol, timeout) -> None:
        # The contacts just sent: counted once, named in last_rejection and on
        # /diagnostics, none in use, and five more joint states' commands stay expected.
        controller = self.node.controller
        assert self.spin_until(lambda: controller.counters.rejected['contacts'] == 1, timeout), \
            controller.last_rejection
        assert why in controller.last_rejection, controller.last_rejection
        assert controller.inputs.contacts is None
        n = len(self.commands)
        for _ in range(5):
            self.send_joint_state(names, positions)
            self.next_command()
        assert len(self.commands) > n
        for _, cmd in self.commands[n:]:
            np.testing.assert_allclose(cmd, expected, atol=atol)
        assert self.spin_until(
            lambda: self.diagnostics and why in self.diagnostics[-1]['last_rejection'], timeout)

    def send_gravity(self, frame, vector) -> None:
        msg = Vector3Stamped()
        msg.header.frame_id = frame
        msg.vector.x, msg.vector.y, msg.vector.z = (float(v) for v in vector)
        self.gravity_pub.publish(msg)

    def close(self) -> None:
        self.node.destroy_node()
        self.tester.destroy_node()
        self.executor.shutdown()
        rclpy.try_shutdown(context=self.context)


class LifecycleHarness(Harness):
    """
    The managed node, driven over its real lifecycle and parameter services.

    It starts unconfigured: its topics appear at configure, its services at start.
    """

    def make_node(self, overrides):
        return GraspTorqueLifecycleNode(context=self.context, parameter_overrides=overrides)

    def ready(self) -> bool:
        if not hasattr(self, 'change_state'):
            t = self.tester
            self.change_state = t.create_client(ChangeState, 'grasp_torque_node/change_state')
            self.get_state = t.create_client(GetState, 'grasp_torque_node/get_state')
            self.set_params = t.create_client(SetParameters,
                                              'grasp_torque_node/set_parameters')
        return (self.change_state.service_is_ready() and self.get_state.service_is_ready()
                and self.set_params.service_is_ready() and self.solve_client.service_is_ready())

    def transition(self, transition_id: int, timeout: float = 10.0) -> bool:
        """Ask the node for a lifecycle transition by its id; say whether it succeeded."""
        request = ChangeState.Request(transition=Transition(id=transition_id))
        return self.call(self.change_state, request, timeout).success

    def state(self) -> str:
        """Read the label of the node's lifecycle state from its get_state service."""
        return self.call(self.get_state, GetState.Request()).current_state.label

    def set_parameters(self, **params) -> list:
        """Set parameters over the node's set_parameters service: one result each."""
        request = SetParameters.Request(parameters=[
            Parameter(k.replace('__', '.'), value=v).to_parameter_msg()
            for k, v in params.items()])
        return list(self.call(self.set_params, request).results)

    def subscribed(self) -> bool:
        """Whether the node's input subscriptions exist and are matched (configured)."""
        return (self.js_pub.get_subscription_count() > 0
                and self.gravity_pub.get_subscription_count() > 0)


class NodeProcess:
    """
    A node's executable as users run it (a child process on this run's domain), and a tester.

    The tester node, in a context of its own, publishes joint states and records the
    effort commands; services of the child are called through :meth:`call`.

    Args:
        module: the executable's module (``python -m module``).
        args: its command line after the module.
        tester_name: the tester node's name.
    """

    def __init__(self, module: str, args: list[str], tester_name: str) -> None:
        env = dict(os.environ, ROS_DOMAIN_ID=str(PROCESS_DOMAIN),
                   ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
        self.child = subprocess.Popen([sys.executable, '-m', module, *args], env=env,
                                      stderr=subprocess.PIPE, text=True)
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=PROCESS_DOMAIN)
        self.tester = rclpy.create_node(tester_name, context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.tester)
        self.commands: list[np.ndarray] = []
        self.tester.create_subscription(Float64MultiArray, 'effort_commands',
                                        lambda m: self.commands.append(np.array(m.data)),
                                        COMMAND_QOS)
        self.pub = self.tester.create_publisher(JointState, 'joint_states',
                                                qos_profile_sensor_data)

    def spin_until(self, predicate, timeout: float) -> bool:
        """Spin the tester until ``predicate()`` or ``timeout`` [s]; return predicate()."""
        end = time.monotonic() + timeout
        while not predicate() and time.monotonic() < end:
            self.executor.spin_once(timeout_sec=0.01)
        return predicate()

    def call(self, client, request, timeout: float = 30.0):
        """Call a service of the child and return its answer (asserted to come)."""
        assert self.spin_until(client.service_is_ready, timeout)
        future = client.call_async(request)
        assert self.spin_until(future.done, timeout)
        return future.result()

    def first_command(self, names: list[str], positions: list[float],
                      timeout: float = 10.0) -> bool:
        """Publish a joint state until the child's first command arrives."""
        subscribed = self.spin_until(lambda: self.pub.get_subscription_count() > 0, 20.0)
        if not subscribed and self.child.poll() is not None:  # it ended: say why
            raise AssertionError(f'the node exited ({self.child.returncode}) before '
                                 f'subscribing: {self.child.communicate()[1]}')
        assert subscribed, 'the node did not subscribe to joint_states within 20 s'
        end = time.monotonic() + timeout
        while not self.commands and time.monotonic() < end:
            self.pub.publish(JointState(name=names, position=positions))
            self.spin_until(lambda: bool(self.commands), 0.1)
        return bool(self.commands)

    def finish(self, timeout: float = 10.0) -> tuple[int, str]:
        """
        Wait for the child to end; return its exit code and stderr.

        stderr is read while waiting, so that a chatty child cannot block on a full pipe.
        """
        _, err = self.child.communicate(timeout=timeout)
        return self.child.returncode, err

    def close(self) -> None:
        if self.child.poll() is None:
            self.child.kill()
        self.tester.destroy_node()
        self.executor.shutdown()
        rclpy.try_shutdown(context=self.context)
