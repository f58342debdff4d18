# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Peers that cannot talk to the node's topics, found from the ROS graph.

rclpy gives every publisher and subscription two QoS event handlers by default
(incompatible QoS, incompatible type), each a waitable that its executor walks
on every wait: sixteen of the node's 31 entities, about 80 us of CPU per joint
state at 1 kHz here. The node makes its topics without them, and this module
finds the same two faults by asking the graph instead, once a diagnostics
period: a peer whose message type differs, or whose QoS cannot be matched with
ours (``rclpy.qos.qos_check_compatible``, the rule the middleware applies).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.qos import qos_check_compatible, QoSCompatibility
from rclpy.subscription import Subscription

#: Most peers named in one diagnostics value; the rest are counted.
MAX_LISTED = 5


def quiet_publisher() -> PublisherEventCallbacks:
    """Give event callbacks that make no event handlers for a publisher."""
    return PublisherEventCallbacks(use_default_callbacks=False)


def quiet_subscription() -> SubscriptionEventCallbacks:
    """Give event callbacks that make no event handlers for a subscription."""
    return SubscriptionEventCallbacks(use_default_callbacks=False)


def type_name(msg_type: type) -> str:
    """Give a message class's name as the graph spells it, e.g. ``sensor_msgs/msg/JointState``."""
    package, kind = msg_type.__module__.split('.')[:2]
    return f'{package}/{kind}/{msg_type.__name__}'


@dataclass(frozen=True)
class Peer:
    """One endpoint on a node's topic that cannot be matched with the node's own."""

    topic: str
    node: str  # its node's fully qualified name
    role: str  # 'publisher' or 'subscription': what the peer is
    reason: str
    gid: tuple[int, ...]

    def describe(self) -> str:
        """Say it in a line: the topic, the peer and why."""
        return f'{self.topic}: {self.role} of {self.node} ({self.reason})'


def _full_name(namespace: str, name: str) -> str:
    return f'{namespace.rstrip("/")}/{name}'


def incompatible(node: Any, entity: Any, msg_type: type) -> list[Peer]:
    """
    Find the peers of one of ``node``'s publishers or subscriptions that cannot reach it.

    Args:
        node: the rclpy node that made ``entity``.
        entity: an rclpy ``Publisher`` or ``Subscription`` (its ``topic_name`` is read;
            its QoS, from the graph).
        msg_type: the message class it was made with.

    Returns:
        The peers with another message type or a QoS the middleware will not match, in
        the graph's order.
    """
    topic = entity.topic_name
    ours = type_name(msg_type)
    publishers = node.get_publishers_info_by_topic(topic)
    subscriptions = node.get_subscriptions_info_by_topic(topic)
    publishing = not isinstance(entity, Subscription)
    own, endpoints, role = ((publishers, subscriptions, 'subscription') if publishing
                            else (subscriptions, publishers, 'publisher'))
    name, namespace = node.get_name(), node.get_namespace()
    mine = [i for i in own if i.node_name == name and i.node_namespace == namespace]
    if not mine:
        return []  # not in the graph yet
    # The graph's profile, not entity.qos_profile: the graph gives durations the
    # middleware chose (a default deadline reads as infinite there, 0 in ours), and
    # comparing one with the other finds faults that are not there.
    profile = mine[0].qos_profile
    peers = []
    for info in endpoints:
        if info.node_name == name and info.node_namespace == namespace:
            continue
        if info.topic_type != ours:
            reason = f'type {info.topic_type}, not {ours}'
        else:
            offered, requested = ((profile, info.qos_profile) if publishing
                                  else (info.qos_profile, profile))
            compatibility, why = qos_check_compatible(offered, requested)
            if compatibility != QoSCompatibility.ERROR:
                continue
            reason = 'QoS: ' + '; '.join(
                part.strip().removeprefix('ERROR: ') for part in why.split(';')
                if part.strip().startswith('ERROR'))
        peers.append(Peer(topic, _full_name(info.node_namespace, info.node_name), role,
                          reason, tuple(info.endpoint_gid)))
    return peers


class PeerWatch:
    """
    The node's topics, checked against the graph; each peer found is told once.

    :meth:`check_next` checks one topic a call, in turn (the node's graph timer: a few
    graph queries a tick, never all in one callback), and gives the peers that topic's
    last check did not find (to log); :meth:`peers` gives every incompatible peer known.
    What it remembers is each topic's last check only: bounded by the graph.
    """

    def __init__(self) -> None:
        """Watch nothing yet."""
        self._watched: list[tuple[Any, type]] = []
        self._found: dict[int, list[Peer]] = {}  # watched index -> its last check's peers
        self._next = 0

    def __len__(self) -> int:
        """Give how many topics are watched."""
        return len(self._watched)

    def watch(self, entity: Any, msg_type: type) -> None:
        """Add a publisher or a subscription of the node, made with ``msg_type``."""
        self._watched.append((entity, msg_type))

    def clear(self) -> None:
        """Forget the entities (destroyed) and the peers told."""
        self._watched.clear()
        self._found.clear()
        self._next = 0

    def check_next(self, node: Any) -> list[Peer]:
        """Check the next topic in turn; give the peers its last check did not find."""
        if not self._watched:
            return []
        k = self._next % len(self._watched)
        self._next = k + 1
        return self._check(node, k)

    def checked(self) -> int:
        """Give how many of the watched topics were checked."""
        return len(self._found)

    def checked_all(self) -> bool:
        """Tell whether every watched topic was checked."""
        return len(self._found) == len(self._watched)

    def peers(self) -> list[Peer]:
        """Give the incompatible peers of each topic's last check, in the topics' order."""
        return [p for k in sorted(self._found) for p in self._found[k]]

    def _check(self, node: Any, k: int) -> list[Peer]:
        """Check topic ``k``; keep its peers; give those its last check did not find."""
        entity, msg_type = self._watched[k]
        found = incompatible(node, entity, msg_type)
        before = {(p.topic, p.gid) for p in self._found.get(k, ())}
        self._found[k] = found
        return [p for p in found if (p.topic, p.gid) not in before]


def summary(peers: list[Peer]) -> str:
    """Say the peers in one diagnostics value: 'none', or up to MAX_LISTED and a count."""
    if not peers:
        return 'none'
    text = '; '.join(p.describe() for p in peers[:MAX_LISTED])
    more = len(peers) - MAX_LISTED
    return f'{text}; and {more} more' if more > 0 else text
