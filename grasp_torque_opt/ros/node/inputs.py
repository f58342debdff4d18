# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The node's inputs: subscriptions, the size gate, and messages to plain arrays.

Every input is taken serialized, so that its length is checked before it is
deserialized (``max_message_bytes``); with message info, it is aged from when the
middleware received it. The controller checks the rest (docs/node.md, "Input
checks"); a rejection is logged (throttled) and counted, and never commanded.
A joint state runs one cycle while the node commands: that path is kept short, as it
runs up to a thousand times a second.
"""

from __future__ import annotations

import time
from typing import Any, TYPE_CHECKING

from geometry_msgs.msg import PoseArray, PoseStamped, Vector3Stamped, WrenchStamped
from grasp_torque_opt.control.inputs import stamp_seconds
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.ros.node.qos import JOINT_STATE_QOS
from grasp_torque_opt.ros.peers import quiet_subscription
import numpy as np
from rclpy.qos import qos_profile_sensor_data
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import Imu, JointState

if TYPE_CHECKING:
    from grasp_torque_opt.ros.node.root import GraspTorque


def received(info: dict | None) -> float:
    """
    When the middleware received a message, on the monotonic clock [s].

    rmw's message info carries ``received_timestamp``: the system clock
    (``CLOCK_REALTIME``) of this host when the subscription's middleware took the
    message in, before it waited in the queue for the executor. Its age on the
    system clock, taken from now on the monotonic clock, is the receipt time
    (a clock step between the two counts as no wait; a message without it: now).
    """
    now = time.monotonic()
    ns = (info or {}).get('received_timestamp') or 0
    if ns <= 0:
        return now
    return now - max(0.0, (time.time_ns() - ns) * 1e-9)


class Inputs:
    """The subscriptions of the node and what each does with its messages."""

    def __init__(self, root: GraspTorque) -> None:
        """Belong to ``root``: its lock, controller and outputs."""
        self.root = root
        self.node = root.node
        self.joint_states_topic = ''  # remapped and resolved, once subscribed
        # use_sim_time is fixed after start (DeclaredParameters): read once.
        self.sim_time = bool(root.node.get_parameter('use_sim_time').value)

    def start(self) -> list[Any]:
        """Make the subscriptions (imu with imu.enabled); give them (destroyed at stop)."""
        made = []
        topics = [(JointState, 'joint_states', self.on_joint_state),
                  (PoseArray, 'contacts', self.on_contacts),
                  (WrenchStamped, 'external_wrench', self.on_wrench),
                  (Vector3Stamped, 'gravity', self.on_gravity),
                  (PoseStamped, 'object_pose', self.on_object_pose)]
        if self.root.params.imu.enabled:
            topics.append((Imu, 'imu', self.on_imu))
        for msg_type, topic, take in topics:
            callback = self._callback(topic, msg_type, take)
            qos = JOINT_STATE_QOS if topic == 'joint_states' else qos_profile_sensor_data
            sub = self.node.create_subscription(msg_type, topic, callback, qos, raw=True,
                                                event_callbacks=quiet_subscription())
            made.append(sub)
            self.root.peers.watch(sub, msg_type)
            if topic == 'joint_states':
                self.joint_states_topic = sub.topic_name
        return made

    def _callback(self, topic: str, msg_type: type, take: Any) -> Any:
        if self.root.message_info:
            return lambda data, info: self.on_serialized(topic, msg_type, data, take, info)
        return lambda data: self.on_serialized(topic, msg_type, data, take, None)

    def _rejected(self, e: InputError) -> None:
        self.node.get_logger().warn(f'rejected: {e}', throttle_duration_sec=1.0)

    def clock_now(self) -> float:
        """
        Now on the node's clock (ROS time), the clock of header stamps [s].

        Without sim time, ROS time is the system clock: read directly (rclpy's
        ``Clock.now()`` cost 9 us of the joint state's path). ``use_sim_time`` is fixed
        after start, so the choice holds.
        """
        if not self.sim_time:
            return time.time()
        return self.node.get_clock().now().nanoseconds * 1e-9

    def on_serialized(self, topic: str, msg_type: type, data: bytes, take: Any,
                      info: dict | None) -> None:
        """
        Take a message as the middleware delivered it.

        Its length is checked, then it is deserialized and taken (``take(msg, receipt)``).
        """
        receipt = received(info) if info is not None else None
        with self.root.lock:
            ctrl = self.root.controller
            if ctrl is None:
                return  # released (the managed node's cleanup) while it waited
            try:
                ctrl.check_bytes(topic, len(data))
            except InputError as e:
                self._rejected(e)
                return
        take(deserialize_message(data, msg_type), receipt)

    def on_joint_state(self, msg: JointState, receipt: float | None = None) -> None:
        """
        Take a joint state and, while the node commands, run one cycle on it.

        Args:
            msg: the joint state.
            receipt: when the middleware received it (monotonic [s]; None: now).
        """
        now = time.monotonic()
        receipt = now if receipt is None else receipt
        header = msg.header.stamp
        stamp = stamp_seconds(header.sec, header.nanosec)
        root = self.root
        with root.lock:
            ctrl = root.controller
            if ctrl is None:
                return
            try:
                # The controller checks the sizes first (the bytes are bounded already).
                ctrl.update_joint_state(msg.name, msg.position, receipt, stamp,
                                        self.clock_now(), msg.effort)
            except InputError as e:
                self._rejected(e)
                return
            root.last_stamp = header
            if root.commanding:
                root.outputs.publish(ctrl.cycle(now), header)
                load = ctrl.solving.effort_load
                if load.off and not load.said:
                    load.said = True
                    self.node.get_logger().warn(load.off)

    def on_contacts(self, msg: PoseArray, receipt: float | None = None) -> None:
        """
        Take contact frames in a model frame: one per scenario contact, or per named link.

        ``header.frame_id`` is ``FRAME`` (one pose per scenario contact, by index) or
        ``FRAME;LINK_1,...`` (one pose per named link:
        :mod:`grasp_torque_opt.control.named_contacts`).
        """
        now = time.monotonic() if receipt is None else receipt
        stamp = stamp_seconds(msg.header.stamp.sec, msg.header.stamp.nanosec)
        with self.root.lock:
            ctrl = self.root.controller
            try:
                ctrl.check_size('contacts', len(msg.poses), msg.header.frame_id)
                positions = [[p.position.x, p.position.y, p.position.z] for p in msg.poses]
                quats = [[p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w]
                         for p in msg.poses]
                ctrl.update_contacts(msg.header.frame_id, np.array(positions), np.array(quats),
                                     now, stamp, self.clock_now())
            except InputError as e:
                self._rejected(e)

    def on_wrench(self, msg: WrenchStamped, receipt: float | None = None) -> None:
        """Take the load on the object, in a model frame."""
        now = time.monotonic() if receipt is None else receipt
        stamp = stamp_seconds(msg.header.stamp.sec, msg.header.stamp.nanosec)
        f, t = msg.wrench.force, msg.wrench.torque
        with self.root.lock:
            try:
                self.root.controller.update_wrench(msg.header.frame_id, [f.x, f.y, f.z],
                                                   [t.x, t.y, t.z], now, stamp,
                                                   self.clock_now())
            except InputError as e:
                self._rejected(e)

    def on_gravity(self, msg: Vector3Stamped, receipt: float | None = None) -> None:
        """
        Take gravity [m/s^2] in the hand's base frame (another frame only through tf2).

        g(q) and the scenario's load (its object's weight) follow it; once one has
        arrived, it goes stale after ``gravity_timeout``, as the other inputs do.
        """
        now = time.monotonic() if receipt is None else receipt
        stamp = stamp_seconds(msg.header.stamp.sec, msg.header.stamp.nanosec)
        frame, v = msg.header.frame_id, msg.vector
        with self.root.lock:
            base = self.root.controller.setup.hand.base_frame
        tf = self.root.tf
        rotation, why = (None, 'tf2_ros is not installed')
        if frame not in ('', base) and tf.running:
            rotation, why = tf.rotation(base, frame)
        with self.root.lock:
            try:
                self.root.controller.update_gravity(frame, [v.x, v.y, v.z], now, stamp,
                                                    self.clock_now(), rotation, why)
            except InputError as e:
                self._rejected(e)

    def on_object_pose(self, msg: PoseStamped, receipt: float | None = None) -> None:
        """
        Take the object's pose: in the base frame, a model frame, or any frame tf2 resolves.

        The contacts from geometry and the load's point follow it; rejected (counted,
        logged, not kept): the last accepted pose is used while fresh.
        """
        now = time.monotonic() if receipt is None else receipt
        stamp = stamp_seconds(msg.header.stamp.sec, msg.header.stamp.nanosec)
        frame, p, o = msg.header.frame_id, msg.pose.position, msg.pose.orientation
        with self.root.lock:
            hand = self.root.controller.setup.hand
            known = frame in ('', hand.base_frame) or hand.model.existFrame(frame)
            base = hand.base_frame
        transform, why = None, 'tf2_ros is not installed'
        if not known and self.root.tf.running:
            transform, why = self.root.tf.transform(base, frame)
        with self.root.lock:
            try:
                self.root.controller.store.update_object_pose(
                    frame, [p.x, p.y, p.z], [o.x, o.y, o.z, o.w], now, stamp,
                    self.clock_now(), transform, why)
            except InputError as e:
                self._rejected(e)

    def on_imu(self, msg: Imu, receipt: float | None = None) -> None:
        """
        Take the base's IMU: specific force and angular velocity (imu.enabled).

        In the hand's base frame, or another frame through tf2 (its rotation and origin);
        its orientation is not used. Rejected (counted, logged, not kept): the cycle
        uses the last accepted reading while it is fresh, then the scenario's gravity.
        """
        now = time.monotonic() if receipt is None else receipt
        stamp = stamp_seconds(msg.header.stamp.sec, msg.header.stamp.nanosec)
        frame, a, w = msg.header.frame_id, msg.linear_acceleration, msg.angular_velocity
        with self.root.lock:
            base = self.root.controller.setup.hand.base_frame
        tf = self.root.tf
        transform, why = None, 'tf2_ros is not installed'
        if frame not in ('', base) and tf.running:
            transform, why = tf.transform(base, frame)
        with self.root.lock:
            try:
                self.root.controller.store.update_imu(frame, [a.x, a.y, a.z], [w.x, w.y, w.z],
                                                      now, stamp, self.clock_now(), transform,
                                                      why)
            except InputError as e:
                self._rejected(e)
