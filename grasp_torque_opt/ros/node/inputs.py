# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The node's inputs: subscriptions made from the inputs' table, the size gate, messages to readings.

Every input is taken serialized, so that its length is checked before it is
deserialized (``max_message_bytes``); with message info, it is aged from when the
middleware received it. The controller checks the rest (docs/node.md, "Input
checks"); a rejection is logged (throttled) and counted, and never commanded.
A joint state runs one cycle while the node commands: that path is kept short, as it
runs up to a thousand times a second.

:data:`MESSAGES` gives each input of
:data:`~grasp_torque_opt.control.inputs.registry.REGISTRY` its message class and its
conversion to the input's reading (plain arrays; a frame looked up with tf2 where the
input takes one); a test holds the two tables to each other.
"""

from __future__ import annotations

import time
from typing import Any, TYPE_CHECKING

from geometry_msgs.msg import PoseArray, PoseStamped, Vector3Stamped, WrenchStamped
from grasp_torque_opt.control.inputs.base import NO_TF, stamp_seconds, subscribed
from grasp_torque_opt.control.inputs.contacts import ContactsReading
from grasp_torque_opt.control.inputs.external_wrench import WrenchReading
from grasp_torque_opt.control.inputs.gravity import GravityReading
from grasp_torque_opt.control.inputs.imu import ImuReading
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.inputs.object_pose import PoseReading
from grasp_torque_opt.control.inputs.registry import REGISTRY
from grasp_torque_opt.control.inputs.tactile import TactileArrayReading, TactileWrenchReading
from grasp_torque_opt.control.parameters.snapshot import value_of
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.ros.node.qos import JOINT_STATE_QOS
from grasp_torque_opt.ros.node.throttle import Throttle
from grasp_torque_opt.ros.node.wire import JointStateLayout
from grasp_torque_opt.ros.peers import quiet_subscription
import numpy as np
from rclpy.qos import qos_profile_sensor_data
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import Imu, JointState
from std_msgs.msg import Float32MultiArray

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
        #: The joint states' layout (read without rclpy where the bytes fit it).
        self.layout = JointStateLayout()
        # use_sim_time is fixed after start (DeclaredParameters): read once.
        self.sim_time = bool(root.node.get_parameter('use_sim_time').value)
        self._rejections = Throttle(1.0)

    def start(self) -> list[Any]:
        """Make a subscription per input of the table (an input's ``enabled`` parameter on)."""
        made = []
        # The joint states' subscription last: when messages of several inputs wait
        # together, rclpy's executor takes them in the order their subscriptions were
        # made, so the others are taken before the joint state whose cycle uses them.
        for name, given in sorted(REGISTRY.items(), key=lambda item: item[0] == 'joint_states'):
            if given.enabled and not subscribed(given, value_of(self.root.params,
                                                                given.enabled)):
                continue
            msg_type = MESSAGES[name][0]
            if name == 'joint_states':
                callback = self.on_joint_state_bytes if self.root.message_info else (
                    lambda data: self.on_joint_state_bytes(data, None))
            else:
                callback = self._callback(name, msg_type, lambda msg, receipt, name=name:
                                          self.on_message(name, msg, receipt))
            qos = JOINT_STATE_QOS if given.qos == 'joint_states' else qos_profile_sensor_data
            sub = self.node.create_subscription(msg_type, name, callback, qos, raw=True,
                                                event_callbacks=quiet_subscription())
            made.append(sub)
            self.root.peers.watch(sub, msg_type)
            if name == 'joint_states':
                self.joint_states_topic = sub.topic_name
        return made

    def _callback(self, topic: str, msg_type: type, take: Any) -> Any:
        if self.root.message_info:
            return lambda data, info: self.on_serialized(topic, msg_type, data, take, info)
        return lambda data: self.on_serialized(topic, msg_type, data, take, None)

    def _rejected(self, e: InputError) -> None:
        if self._rejections.due():
            self.node.get_logger().warn(f'rejected: {e}')

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

    @property
    def sim_aged(self) -> bool:
        """Whether inputs are aged on simulated time (``age_on_sim_time``, read-only)."""
        return self.sim_time and bool(getattr(self.root.params, 'age_on_sim_time', False))

    def now(self) -> float:
        """
        Now on the clock that ages inputs and paces the rate rules [s].

        The monotonic clock; with ``use_sim_time`` and ``age_on_sim_time`` the ROS clock
        (simulated time), so that a simulation that waits for the node
        (``grasp-torque-sim --lockstep``) gets the same commands whatever the machine's
        load (docs/node.md, "Which clock ages an input").
        """
        if not self.sim_aged:
            return time.monotonic()
        return self.node.get_clock().now().nanoseconds * 1e-9

    def on_serialized(self, topic: str, msg_type: type, data: bytes, take: Any,
                      info: dict | None) -> None:
        """
        Take a message as the middleware delivered it.

        Its length is checked, then it is deserialized and taken (``take(msg, receipt)``).
        """
        admitted, receipt = self._admitted(topic, data, info)
        if admitted:
            take(deserialize_message(data, msg_type), receipt)

    def _admitted(self, topic: str, data: bytes, info: dict | None
                  ) -> tuple[bool, float | None]:
        """Check a message's length while the node runs; give (taken, its receipt time)."""
        receipt = received(info) if info is not None and not self.sim_aged else None
        with self.root.lock:
            ctrl = self.root.controller
            if ctrl is None:
                return False, receipt  # released (the managed node's cleanup) meanwhile
            try:
                ctrl.check_bytes(topic, len(data))
            except InputError as e:
                self._rejected(e)
                return False, receipt
        return True, receipt

    def on_joint_state_bytes(self, data: bytes, info: dict | None) -> None:
        """
        Take a joint state as the middleware delivered it (as :meth:`on_serialized`).

        Its length is checked; then it is read by the layout of the last joint state
        rclpy read (:class:`~grasp_torque_opt.ros.node.wire.JointStateLayout`: the same
        bytes but for the stamp and the values), else deserialized by rclpy.
        """
        admitted, receipt = self._admitted('joint_states', data, info)
        if not admitted:
            return
        read = self.layout.read(data)
        if read is None:
            msg = deserialize_message(data, JointState)
            self.layout.learn(data, msg)
            read = msg.header.stamp, msg.name, msg.position, msg.effort
        self.joint_state(*read, receipt)

    def on_joint_state(self, msg: JointState, receipt: float | None = None) -> None:
        """
        Take a joint state and, while the node commands, run one cycle on it.

        Args:
            msg: the joint state.
            receipt: when the middleware received it (monotonic [s]; None: now).
        """
        self.joint_state(msg.header.stamp, msg.name, msg.position, msg.effort, receipt)

    def joint_state(self, header: Any, names: Any, positions: Any, efforts: Any,
                    receipt: float | None = None) -> None:
        """Take a joint state's stamp, names, positions and efforts (:meth:`on_joint_state`)."""
        now = self.now()
        stamp = stamp_seconds(header.sec, header.nanosec)
        if self.sim_aged:
            # /clock and joint_states are two topics: no order between them is sure, and
            # a cycle run before its /clock would see no time pass (a lockstep run would
            # then depend on the machine's load). The joint state's stamp is the time.
            now = max(now, stamp)
        receipt = now if receipt is None else receipt
        root = self.root
        with root.lock:
            ctrl = root.controller
            if ctrl is None:
                return
            try:
                # The store checks the sizes first (the bytes are bounded already).
                ctrl.take('joint_states', JointStateReading(names, positions, efforts),
                          receipt, stamp, self.clock_now())
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

    def on_message(self, name: str, msg: Any, receipt: float | None = None) -> None:
        """
        Take a message of the input ``name`` (any but the joint states): convert, check, keep.

        The conversion (:data:`MESSAGES`) may look a frame up with tf2, outside the lock;
        a rejection is logged (throttled) and counted, never commanded.
        """
        now = self.now() if receipt is None else receipt
        header = getattr(msg, 'header', None)  # a std_msgs array has none: unstamped
        stamp = 0.0 if header is None else stamp_seconds(header.stamp.sec, header.stamp.nanosec)
        with self.root.lock:
            ctrl = self.root.controller
            if ctrl is None:
                return
            hand = ctrl.setup.hand
        try:
            reading = MESSAGES[name][1](self, msg, hand)
            with self.root.lock:
                ctrl = self.root.controller
                if ctrl is None:
                    return
                ctrl.take(name, reading, now, stamp, self.clock_now())
        except InputError as e:
            self._rejected(e)

    def looked_up(self, hand: Any, frame: str) -> tuple:
        """
        Return ``frame``'s transform to the hand's base frame by tf2, and why not.

        Gives (None, why) for the base frame itself, a model frame, or without tf2.
        """
        if frame in ('', hand.base_frame) or hand.model.existFrame(frame) \
                or not self.root.tf.running:
            return None, NO_TF
        return self.root.tf.transform(hand.base_frame, frame)


def _contacts(inputs: Inputs, msg: PoseArray, hand: Any) -> ContactsReading:
    """Give the contacts' reading; its count is checked against the frame_id first."""
    with inputs.root.lock:
        inputs.root.controller.check_size('contacts', len(msg.poses), msg.header.frame_id)
    positions = [[p.position.x, p.position.y, p.position.z] for p in msg.poses]
    quats = [[p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w]
             for p in msg.poses]
    return ContactsReading(msg.header.frame_id, np.array(positions), np.array(quats))


def _wrench(inputs: Inputs, msg: WrenchStamped, hand: Any) -> WrenchReading:
    f, t = msg.wrench.force, msg.wrench.torque
    return WrenchReading(msg.header.frame_id, [f.x, f.y, f.z], [t.x, t.y, t.z])


def _gravity(inputs: Inputs, msg: Vector3Stamped, hand: Any) -> GravityReading:
    """Give gravity's reading, another frame than the base's only through tf2 (its rotation)."""
    frame, v = msg.header.frame_id, msg.vector
    rotation, why = (None, NO_TF) if frame in ('', hand.base_frame) \
        or not inputs.root.tf.running else inputs.root.tf.rotation(hand.base_frame, frame)
    return GravityReading(frame, [v.x, v.y, v.z], rotation, why)


def _imu(inputs: Inputs, msg: Imu, hand: Any) -> ImuReading:
    """Give the IMU's reading, another frame than the base's through tf2; no orientation."""
    frame, a, w = msg.header.frame_id, msg.linear_acceleration, msg.angular_velocity
    transform, why = (None, NO_TF) if frame in ('', hand.base_frame) \
        or not inputs.root.tf.running else inputs.root.tf.transform(hand.base_frame, frame)
    return ImuReading(frame, [a.x, a.y, a.z], [w.x, w.y, w.z], transform, why)


def _object_pose(inputs: Inputs, msg: PoseStamped, hand: Any) -> PoseReading:
    """Give the object pose's reading: base or model frame, or any frame tf2 resolves."""
    frame, p, o = msg.header.frame_id, msg.pose.position, msg.pose.orientation
    transform, why = inputs.looked_up(hand, frame)
    return PoseReading(frame, [p.x, p.y, p.z], [o.x, o.y, o.z, o.w], transform, why)


def _tactile(inputs: Inputs, msg: Float32MultiArray, hand: Any) -> TactileArrayReading:
    """Give the tactile array's reading; its length is checked against tactile.links first."""
    with inputs.root.lock:
        inputs.root.controller.check_size('tactile', len(msg.data))
    return TactileArrayReading(np.asarray(msg.data, dtype=float))


def _tactile_wrench(inputs: Inputs, msg: WrenchStamped, hand: Any) -> TactileWrenchReading:
    f, t = msg.wrench.force, msg.wrench.torque
    return TactileWrenchReading(msg.header.frame_id, [f.x, f.y, f.z], [t.x, t.y, t.z])


#: Input name -> (its message class, its conversion (inputs, message, hand) -> reading);
#: the joint states are converted on their own short path (:meth:`Inputs.on_joint_state`).
MESSAGES: dict[str, tuple[type, Any]] = {
    'joint_states': (JointState, None),
    'contacts': (PoseArray, _contacts),
    'external_wrench': (WrenchStamped, _wrench),
    'gravity': (Vector3Stamped, _gravity),
    'imu': (Imu, _imu),
    'object_pose': (PoseStamped, _object_pose),
    'tactile': (Float32MultiArray, _tactile),
    'tactile_wrench': (WrenchStamped, _tactile_wrench),
}
