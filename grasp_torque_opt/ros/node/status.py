# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The node's /diagnostics: the controller's report, and what only the ROS graph tells.

The controller's part is a pure function of it (:func:`grasp_torque_opt.control.
diagnostics.report`); here it gets the graph's: publishers on joint_states, other
nodes of this name, incompatible peers, the executor thread, the lifecycle state.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from grasp_torque_opt.control import diagnostics
from grasp_torque_opt.ros import realtime
from grasp_torque_opt.ros.peers import quiet_publisher, summary

if TYPE_CHECKING:
    from grasp_torque_opt.ros.node.root import GraspTorque

#: Steps of the graph checks per diagnostics period (:meth:`Status.on_graph`): with the
#: Allegro's thirteen watched topics and the command topic, a whole round takes about
#: 1.4 periods.
GRAPH_STEPS = 10


class Status:
    """The /diagnostics publisher and the graph checks it reports."""

    def __init__(self, root: GraspTorque) -> None:
        """Belong to ``root``."""
        self.root = root
        self.node = root.node
        self.pub = None
        self.duplicates = 0  # other nodes of this name, at the last report
        #: The other publishers on the command topic, as the graph timer last found them
        #: (:meth:`on_graph`; None: not checked yet). The peers are the PeerWatch's.
        self.rivals: list[str] | None = None
        self._graph_step = 0
        self._pending = None  # the status being made (_status_steps), None: none

    def start(self) -> list:
        """Make the publisher; give it for the root to destroy."""
        self.pub = self.node.create_publisher(DiagnosticArray, '/diagnostics', 10,
                                              event_callbacks=quiet_publisher())
        self.root.peers.watch(self.pub, DiagnosticArray)
        return [self.pub]

    def stop(self) -> None:
        """Forget the publisher (destroyed by the root) and what the graph checks found."""
        self.pub = None
        self.rivals = None
        self._graph_step = 0
        self._pending = None

    def count_duplicates(self) -> int:
        """Count the other nodes of this node's name and namespace that the graph shows."""
        node = self.node
        me = (node.get_name(), node.get_namespace())
        return sum(1 for n in node.get_node_names_and_namespaces() if tuple(n) == me) - 1

    def wait_for_duplicates(self, seconds: float) -> int:
        """
        Look for other nodes of this name for up to ``seconds``.

        Discovery took 0.2 to 2.8 s here. Nothing spins meanwhile: nothing is taken or
        published.

        Returns:
            How many were seen (0 after ``seconds``).
        """
        end = time.monotonic() + seconds
        while True:
            n = self.count_duplicates()
            if n > 0 or time.monotonic() >= end:
                return n
            time.sleep(0.05)

    def command_rivals(self) -> list[str]:
        """
        Name the other nodes that publish on this node's command topic (from the graph).

        Two nodes remapped to one controller's topic interleave their commands (one's
        zeros with the other's torques); a foreign publisher may do the same.
        """
        node = self.node
        me = (node.get_namespace(), node.get_name())
        topic = self.root.outputs.command_pub.topic_name
        return [f"{i.node_namespace.rstrip('/')}/{i.node_name}"
                for i in node.get_publishers_info_by_topic(topic)
                if (i.node_namespace, i.node_name) != me]

    def on_graph(self) -> None:
        """
        Take one step of the graph checks (the graph timer).

        The steps go round: the command topic's other publishers, then each watched topic's
        incompatible peers (:meth:`PeerWatch.check_next`). One or two graph queries a
        tick: the whole check, some thirty queries and the QoS profiles they make, took
        about half a millisecond in one callback, and a 1 kHz joint state arriving then
        was overwritten by the next (the subscription keeps the last one only).
        """
        if self.step_status():  # a status being made goes first
            return
        node, log = self.node, self.node.get_logger()
        step = self._graph_step
        self._graph_step += 1
        if step % (len(self.root.peers) + 1) == 0:
            self.rivals = self.command_rivals()
            return
        for peer in self.root.peers.check_next(node):
            log.warn(f'{peer.describe()}: no messages will pass between it and this node')

    def on_diagnostics(self) -> None:
        """
        Start one diagnostic status (the diagnostics timer): the controller's report now.

        The status is made in steps (:meth:`_status_steps`), the first here, the others
        on the graph timer's next ticks (:meth:`on_graph`), a few tenths of a
        millisecond each: made whole, the report, its eighty-odd key-value pairs and
        their publishing took about half a millisecond, and a 1 kHz joint state
        arriving then was overwritten by the next.
        """
        if self._pending is not None:  # the last one's steps not all taken: finish it
            for _ in self._pending:
                pass
        self._pending = self._status_steps()
        self.step_status()

    def step_status(self) -> bool:
        """Take the next step of the status being made; tell whether one was taken."""
        if self._pending is None:
            return False
        if next(self._pending, None) is None:
            self._pending = None
        return True

    def _status_steps(self):
        """Make and publish one status, yielding between its steps (:meth:`on_diagnostics`)."""
        root, node = self.root, self.node
        log = node.get_logger()
        with root.lock:
            now = time.monotonic()
            rep = diagnostics.report(root.controller, now)
            gravity_time = root.controller.inputs.gravity_time
            # The hand's name from its URDF (e.g. allegro_hand_right), as hardware_id asks.
            hand = root.controller.setup.hand.model.name
        stamp = node.get_clock().now().to_msg()  # the report's time, not the publishing's
        yield True
        # Two sources of joint states are followed as one stream (the stamp rule keeps
        # either from locking the other out); say so, as the node cannot tell them apart.
        topic = root.inputs.joint_states_topic
        publishers = node.count_publishers(topic)
        if publishers > 1:
            log.warn(f'{publishers} publishers on {topic}: their joint states are taken as '
                     'one stream', throttle_duration_sec=10.0)
        values = [*rep.values, ('joint_states.publishers', str(publishers)),
                  ('age.gravity_s', 'never' if gravity_time is None
                   else f'{now - gravity_time:.4f}')]
        if not any(k == 'rejected.gravity' for k, _ in values):
            values.append(('rejected.gravity', '0'))  # counted from its first rejection
        level, message = rep.level, rep.message
        if not root.commanding:
            level, message = diagnostics.STALE, f'inactive (lifecycle): no commands; {message}'
        self.duplicates = self.count_duplicates()  # about 1 us: rmw's graph cache
        if self.duplicates > 0:
            name = node.get_fully_qualified_name()
            log.error(f'another node named {name} is on this domain: both may drive '
                      'effort_commands and take parameters', throttle_duration_sec=10.0)
            level = diagnostics.ERROR
            message = f'another node named {name} is on this domain; {message}'
        values.append(('duplicate_nodes', str(self.duplicates)))
        others = self.rivals or []
        values.append(('command_topic.other_publishers', 'not checked yet' if self.rivals is None
                       else ', '.join(others) or 'none'))
        if others:
            topic = root.outputs.command_pub.topic_name
            log.error(f'another publisher on {topic}: {", ".join(others)}; the effort '
                      'controller takes commands from both', throttle_duration_sec=10.0)
            level = diagnostics.ERROR
            message = f'another publisher on {topic} ({", ".join(others)}); {message}'
        values.append(('executor_thread', realtime.describe()))  # this callback's thread
        # What rclpy's default QoS event handlers would have logged, found from the graph
        # (told when found, by on_graph).
        watch = root.peers
        peers = watch.peers()
        values.append(('incompatible_peers', summary(peers) if peers or watch.checked_all()
                       else f'none in {watch.checked()} of {len(watch)} topics so far'))
        if peers:
            level = max(level, diagnostics.WARN)  # at least WARN (STALE and ERROR stay)
            message = f'{len(peers)} incompatible peer(s) on its topics; {message}'
        yield True
        # The fully qualified name: two nodes in two namespaces are told apart.
        status = DiagnosticStatus(level=bytes([level]), name=f'{node.get_fully_qualified_name()}'
                                  ': grasp torques', message=message, hardware_id=hand,
                                  values=[KeyValue(key=k, value=v) for k, v in values])
        msg = DiagnosticArray(status=[status])
        msg.header.stamp = stamp
        yield True
        self.pub.publish(msg)
