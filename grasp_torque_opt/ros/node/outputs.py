# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The node's outputs: the commands in the driver's units, the stamped copy, the RViz arrows.

A command leaves only through :meth:`Outputs.publish`, which keeps the node's own
promise whatever the controller decided: the right length, finite, within the
limits, and its message in the ``command_interface``'s units the same (right length,
finite, of that interface). The publisher's topic and type are the interface's
(:data:`~grasp_torque_opt.control.commands.registry.REGISTRY`): ``effort_commands``
(std_msgs/Float64MultiArray, unchanged), ``position_commands`` and ``current_commands``
(Float64MultiArray), ``hybrid_commands`` (sensor_msgs/JointState). The managed node's
command publishers are lifecycle publishers (silent unless active): the root's
configuration says which kind to make.
"""

from __future__ import annotations

from array import array
from typing import Any, TYPE_CHECKING

from geometry_msgs.msg import Point, WrenchStamped
from grasp_torque_opt.control.commands.base import Command
from grasp_torque_opt.control.commands.registry import REGISTRY
from grasp_torque_opt.control.fault_policy import CycleResult
from grasp_torque_opt.control.geometry import placements_at
from grasp_torque_opt.ros.node.qos import COMMAND_QOS
from grasp_torque_opt.ros.node.throttle import Throttle
from grasp_torque_opt.ros.node.wire import Serialized
from grasp_torque_opt.ros.peers import quiet_publisher
import numpy as np
from rclpy.duration import Duration
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray
from visualization_msgs.msg import Marker, MarkerArray

if TYPE_CHECKING:
    from grasp_torque_opt.ros.node.root import GraspTorque


class Outputs:
    """The command publishers and the marker publisher."""

    def __init__(self, root: GraspTorque) -> None:
        """Belong to ``root``: its node, its controller and its configuration."""
        self.root = root
        self.node = root.node
        self.command_pub: Any = None
        self.stamped_pub: Any = None
        self.marker_pub: Any = None
        self.wrench_pub: Any = None
        #: The one Float64MultiArray every command leaves in (its data set each time:
        #: rclpy converts a message when it is published, so none is kept half-written).
        self._array = Float64MultiArray()
        #: The commands' bytes by their layouts (:class:`.wire.Serialized`; None: the
        #: layout could not be learnt, messages are published), by (kind, joint names,
        #: frame).
        self._wire: dict[tuple, Serialized | None] = {}
        self._no_command = Throttle(1.0)

    def start(self) -> list[tuple[str, Any]]:
        """Make the publishers; give them as (kind, publisher) for :meth:`stop`."""
        node, peers = self.node, self.root.peers
        entry = REGISTRY[self.root.params.command_interface]
        kind = JointState if entry.message == 'joint_state' else Float64MultiArray
        self.command_pub = self._command_publisher(kind, entry.topic)
        made = [('command_publisher', self.command_pub)]
        peers.watch(self.command_pub, kind)
        self.stamped_pub = None
        if self.root.params.publish_stamped_command:
            self.stamped_pub = self._command_publisher(JointState, '~/effort_commands_stamped')
            made.append(('command_publisher', self.stamped_pub))
            peers.watch(self.stamped_pub, JointState)
        self.marker_pub = node.create_publisher(MarkerArray, '~/contact_wrenches', 1,
                                                event_callbacks=quiet_publisher())
        made.append(('publisher', self.marker_pub))
        peers.watch(self.marker_pub, MarkerArray)
        self.wrench_pub = node.create_publisher(WrenchStamped, '~/contact_wrench', 10,
                                                event_callbacks=quiet_publisher())
        made.append(('publisher', self.wrench_pub))
        peers.watch(self.wrench_pub, WrenchStamped)
        return made

    def _command_publisher(self, msg_type: type, topic: str) -> Any:
        if self.root.managed:
            return self.node.create_lifecycle_publisher(msg_type, topic, COMMAND_QOS,
                                                        event_callbacks=quiet_publisher())
        return self.node.create_publisher(msg_type, topic, COMMAND_QOS,
                                          event_callbacks=quiet_publisher())

    def destroy(self, kind: str, publisher: Any) -> None:
        """Destroy a publisher made by :meth:`start`."""
        if kind == 'command_publisher' and self.root.managed:
            self.node.destroy_lifecycle_publisher(publisher)
        else:
            self.node.destroy_publisher(publisher)

    def stop(self) -> None:
        """Forget the publishers (destroyed by the root)."""
        self.command_pub = self.stamped_pub = self.marker_pub = self.wrench_pub = None

    def publish(self, result: CycleResult, stamp: Any = None) -> None:
        """
        Publish a cycle's command, if it has one and keeps the node's promise.

        Args:
            result: the controller's decision.
            stamp: the header stamp of the joint state it answers (None: now).
        """
        if result.fault and self._no_command.due():
            self.node.get_logger().warn(f'no command: {result.fault}')
        cmd = result.command
        if cmd is None:
            return
        hand = self.root.controller.setup.hand
        # The node's own promise, whatever the controller decided.
        if cmd.shape != (hand.m,) or not np.isfinite(cmd).all() or \
                (np.abs(cmd) > hand.torque_limits).any():
            self.node.get_logger().error('refused to publish a malformed command')
            return
        data = array('d', cmd.tobytes())
        out = result.output
        if out is None and self.root.params.command_interface == 'effort':
            out = Command('effort', cmd, cmd)  # a result made without its interface's output
        if out is None or out.interface != self.root.params.command_interface or \
                not out.well_formed(hand.m, cmd):
            if out is not None:
                self.node.get_logger().error('refused to publish a malformed command')
            return
        self._publish_output(out, data, stamp)
        if self.stamped_pub is not None:
            stamp = stamp if stamp is not None else self.node.get_clock().now().to_msg()
            wire = self._layout('stamped', hand)
            if wire is not None:
                self.stamped_pub.publish(wire.write(data, stamp))
                return
            msg = JointState(name=list(hand.joints), effort=data)
            msg.header.stamp = stamp
            msg.header.frame_id = hand.base_frame
            self.stamped_pub.publish(msg)

    def _layout(self, kind: str, hand: Any) -> Serialized | None:
        """Return the bytes' layout of a command (``array`` or ``stamped``) of this hand."""
        key = (kind, tuple(hand.joints), hand.base_frame)
        if key not in self._wire:
            if kind == 'array':
                msg, field, stamped = Float64MultiArray(), 'data', False
            else:
                msg, field, stamped = JointState(name=list(hand.joints)), 'effort', True
                msg.header.frame_id = hand.base_frame
            try:
                self._wire[key] = Serialized(msg, field, hand.m, stamped)
            except ValueError as e:  # never expected: messages are published then
                self.node.get_logger().warn(f'commands published as messages: {e}')
                self._wire[key] = None
        return self._wire[key]

    def _publish_output(self, out: Command, data: Any = None, stamp: Any = None) -> None:
        """Publish a command in its interface's message (effort: ``data``, the torques)."""
        if out.position is None:  # Float64MultiArray
            values = data if out.interface == 'effort' and data is not None else \
                array('d', np.ascontiguousarray(out.values, dtype=float).tobytes())
            hand = self.root.controller.setup.hand
            wire = self._layout('array', hand) if len(values) == hand.m else None
            if wire is not None:
                self.command_pub.publish(wire.write(values))
                return
            msg = self._array
            msg.data = values
            self.command_pub.publish(msg)
            return
        hand = self.root.controller.setup.hand
        msg = JointState(name=list(hand.joints), position=out.position.tolist(),
                         velocity=out.velocity.tolist(), effort=out.values.tolist())
        msg.header.stamp = stamp if stamp is not None else self.node.get_clock().now().to_msg()
        msg.header.frame_id = hand.base_frame
        self.command_pub.publish(msg)

    def publish_zeros(self, zero: Command | None) -> bool:
        """Publish the interface's zero torque (the safe stop of ``fault_policy: zero``)."""
        if zero is None:
            return False
        self._publish_output(zero)
        return True

    def on_markers(self) -> None:
        """
        Publish the last solution's contact forces as arrows (none when it has none).

        Each of the two topics only while something subscribes to it (RViz, a logger):
        at 10 Hz their making and sending cost the 1 kHz cycle a joint state now and
        then, for no reader.
        """
        root = self.root
        arrows = self.marker_pub.get_subscription_count() > 0
        per_link = self.wrench_pub.get_subscription_count() > 0
        if not (arrows or per_link):
            return
        stamp = self.node.get_clock().now().to_msg()
        with root.lock:
            last = root.controller.last if root.commanding else None
            hand = root.controller.setup.hand
            wrenches = link_wrenches(last, hand) if per_link else []
        if arrows:
            self.marker_pub.publish(markers(last, hand.base_frame, stamp,
                                            root.params.marker_scale,
                                            root.params.marker_period))
        for link, w in wrenches:
            msg = WrenchStamped()
            msg.header.frame_id, msg.header.stamp = link, stamp
            f, t = msg.wrench.force, msg.wrench.torque
            f.x, f.y, f.z, t.x, t.y, t.z = (float(v) for v in w)
            self.wrench_pub.publish(msg)


def link_wrenches(last: CycleResult | None, hand: Any) -> list[tuple[str, np.ndarray]]:
    """
    Give a certified command's contact wrenches in their links' frames (~/contact_wrench).

    Each is the wrench the link applies to the object at its contact (the force, and the
    torsional moment about the normal), moved to the link frame's origin and expressed
    in its axes: [F, M about the link origin], a frame tf knows (robot_state_publisher's).
    The command's own wrenches: a rate-rule step's when it was one. Call under the lock
    (it places the links in the hand's data).
    """
    if last is None or last.kind != 'solution' or last.q is None or last.maps is None:
        return []
    w = last.wrenches if last.wrenches is not None else last.solution.wrenches
    placement = placements_at(hand, last.q)
    out = []
    for frame, wi in zip(last.maps.contacts, w):
        oMl = placement(frame.link)
        force = frame.rotation @ wi[:3]
        torque = np.cross(frame.position - oMl.translation, force) + frame.rotation[:, 2] * wi[3]
        R = oMl.rotation
        out.append((frame.link, np.concatenate((R.T @ force, R.T @ torque))))
    return out


def markers(last: CycleResult | None, base: str, stamp: Any, scale: float,
            period: float) -> MarkerArray:
    """
    Draw a cycle's contact forces as arrows, in the hand's base frame.

    Args:
        last: the cycle (None, or one without a solution: only the clearing marker).
        base: the base frame.
        stamp: their header stamp.
        scale: arrow length per newton [m/N].
        period: the marker period [s]; each arrow lives three.
    """
    clear = Marker(action=Marker.DELETEALL)
    if last is None or last.kind != 'solution' or last.maps is None:  # None: no contacts
        return MarkerArray(markers=[clear])
    out = [clear]
    lifetime = Duration(seconds=3 * period).to_msg()
    for i, (frame, w) in enumerate(zip(last.maps.contacts, last.solution.wrenches)):
        force = frame.rotation @ w[:3]
        start, end = frame.position, frame.position + scale * force
        m = Marker(type=Marker.ARROW, action=Marker.ADD, ns='contact_force', id=i)
        m.header.frame_id, m.header.stamp = base, stamp
        m.points = [Point(x=float(start[0]), y=float(start[1]), z=float(start[2])),
                    Point(x=float(end[0]), y=float(end[1]), z=float(end[2]))]
        m.pose.orientation.w = 1.0
        m.scale.x, m.scale.y, m.scale.z = 0.002, 0.004, 0.004
        m.color.g, m.color.a = 0.8, 1.0
        m.lifetime = lifetime
        out.append(m)
    return MarkerArray(markers=out)
