# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The protocol every node input implements, and what the inputs' modules share.

An input is one module of this package with one object implementing
:class:`NodeInput` and a plain reading type (what the ROS side converts its message
to). The store calls ``check`` and, if the message is accepted, ``keep``; the cycle's
staleness asks ``stale``.
"""

from __future__ import annotations

from typing import Any, Protocol, TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # the store is the composition root of the inputs
    from grasp_torque_opt.control.inputs.store import Inputs, InputStore
    from grasp_torque_opt.control.parameters.generated import CycleConfig

#: Why a frame other than the base's could not be looked up, when nothing says more.
NO_TF = 'tf2_ros is not installed'
#: The QoS an input is subscribed with: the joint states' own (reliable, a short
#: queue: docs/node.md, "Topics, message types and QoS"), or rclpy's sensor-data profile.
QOS = ('joint_states', 'sensor_data')


class NodeInput(Protocol):
    """
    A node input: what the store and the subscriptions need to know of it.

    Attributes:
        name: the topic (before remapping), the key of its counters, stamp mark and
            messages (``rejected.NAME`` on /diagnostics).
        message: its ROS message type, ``package/msg/Type`` (the ROS side's table maps
            it to the class).
        qos: one of :data:`QOS`.
        counted: whether its rejection counter is shown from the start (an optional
            input's from its first rejection).
        enabled: the parameter that subscribes it (None: always subscribed): when true,
            or, for an input with an ``enabled_when`` attribute, when it has that value
            (:func:`subscribed`).
        timeout: the parameter of its freshness rule, in words (docs).
        grasp_only: it describes the grasp (contacts, load, object): its staleness does
            not stop commands while the hand holds nothing (``hold_object`` false).
    """

    name: str
    message: str
    qos: str
    counted: bool
    enabled: str | None
    timeout: str
    grasp_only: bool

    def check(self, store: InputStore, reading: Any) -> Any:
        """Check a reading whole; return the value to keep (raises InputError: not kept)."""

    def keep(self, store: InputStore, value: Any, now: float) -> dict[str, Any]:
        """Keep an accepted value: the snapshot's fields it sets (and its own state)."""

    def stamp_timeout(self, config: CycleConfig) -> float:
        """Return how long its header stamp mark holds [s] (0: joint_state_timeout)."""

    def stale(self, inputs: Inputs, config: CycleConfig, now: float) -> str:
        """Say why its latest value cannot be used at ``now`` ('' if it can, or none came)."""


def subscribed(given: NodeInput, value: Any) -> bool:
    """Say whether ``given`` is subscribed when its ``enabled`` parameter is ``value``."""
    want = getattr(given, 'enabled_when', None)
    return bool(value) if want is None else value == want


def stamp_seconds(sec: int, nanosec: int) -> float:
    """Return a builtin_interfaces/Time as seconds (0.0 for an unstamped message)."""
    return sec + 1e-9 * nanosec


def latest_q(store: InputStore) -> np.ndarray:
    """Return the latest accepted joint positions (the scenario's before the first)."""
    return store.setup.q if store.inputs.q is None else store.inputs.q


def aged(name: str, time: float | None, timeout: float, now: float) -> str:
    """Say ``NAME stale (AGE s > TIMEOUT s)`` when a value that came is too old ('' if not)."""
    if time is not None and timeout > 0 and now - time > timeout:
        return f'{name} stale ({now - time:.3f} s > {timeout} s)'
    return ''
