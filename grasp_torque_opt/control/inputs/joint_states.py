# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The joint states (sensor_msgs/JointState): the positions the cycle runs at, and efforts.

Names and positions, any order, extra joints ignored: only the positions of model joints
are used, so NaN elsewhere (velocity, effort, unknown joints) is accepted. Names that
are not model joints are ignored (a robot's joint_states lists every joint), but must be
unique. The efforts are read only with ``effort_estimation`` (empty or not finite:
none, the store's ``effort_missing`` says why; never a rejection).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

from grasp_torque_opt.control.checks import (
    check_joint_limits,
    check_joint_names,
    MAX_ABS_JOINT_POSITION,
)
from grasp_torque_opt.control.motion import efforts_of
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.native.loader import fast_cycle
import numpy as np


@dataclass(frozen=True)
class JointStateReading:
    """
    A joint state as plain data.

    Attributes:
        names: joint names.
        positions: their positions [rad or m].
        efforts: their measured efforts [N m] (None or empty: none reported).
    """

    names: Sequence[str]
    positions: Sequence[float]
    efforts: Sequence[float] | None = None


class JointStates:
    """The joint states input (:class:`~grasp_torque_opt.control.inputs.base.NodeInput`)."""

    name = 'joint_states'
    message = 'sensor_msgs/msg/JointState'
    qos = 'joint_states'
    counted = True
    enabled = None
    timeout = 'joint_state_timeout'
    grasp_only = False

    def size(self, store, n: int, frame_id: str = '') -> None:
        """Refuse more than ``max_joint_state_entries`` names or positions, unread."""
        limit = store.config.max_joint_state_entries
        if n > limit:
            raise InputError('joint_states', f'{n} entries, more than '
                             f'max_joint_state_entries ({limit})')

    def check(self, store, reading: JointStateReading) -> tuple[np.ndarray, Any]:
        """
        Check a joint state; give (q, the names' check to keep, or None: the last one's).

        Raises:
            InputError: more than ``max_joint_state_entries`` entries, length
                mismatch, empty or duplicate name, a commanded joint missing, a used
                position not finite, beyond
                :data:`~grasp_torque_opt.control.checks.MAX_ABS_JOINT_POSITION` or its
                URDF limits.
        """
        names, positions = reading.names, reading.positions
        self.size(store, max(len(names), len(positions)))
        q = (store.setup.q if store.inputs.q is None else store.inputs.q).copy()
        known = store.joint_names
        lower, upper = store.position_limits()
        if known is not None and known[3] is store.setup.hand.joints and \
                len(positions) == len(names) and names == known[0]:
            # The same names as the last accepted state (a driver's every message): their
            # checks hold; one comparison with the used joints' bounds (within the URDF
            # limits and the magnitude bound) checks the positions. NaN fails it, and
            # then the full checks below name the position and the rule. In one compiled
            # call where the module is built (every joint state: 3 us in numpy).
            low, high = used_bounds(store, known, lower, upper)
            if fast_cycle is not None:
                if fast_cycle.take_positions(positions, known[1], low, high, q, known[2]):
                    return q, None, reading
            else:
                values = np.asarray(positions, dtype=float)[known[1]]
                if ((values >= low) & (values <= high)).all():
                    q[known[2]] = values
                    return q, None, reading
        checked = check_joint_names(names, positions, q, store.model_joints,
                                    store.setup.hand.joints)
        check_joint_limits(q, checked[2], lower, upper, store.q_names,
                           store.config.joint_limit_tolerance)
        return q, checked, reading

    def keep(self, store, value, now: float) -> dict[str, Any]:
        """Keep q (and the names' check, the efforts with effort_estimation)."""
        q, checked, reading = value
        if checked is not None:
            store.joint_names = checked
        effort = None
        if store.config.effort_estimation:
            effort, store.effort_missing, store.effort_index = efforts_of(
                reading.names, reading.efforts, store.setup.hand.joints, store.effort_index)
        return {'q': q, 'q_time': now, 'effort': effort, 'effort_why': store.effort_missing}

    def stamp_timeout(self, config) -> float:
        """Return joint_state_timeout."""
        return config.joint_state_timeout

    def stale(self, inputs, config, now: float) -> str:
        """Say 'no joint state yet', or that the last one is older than its timeout."""
        if inputs.q is None:
            return 'no joint state yet'
        age, timeout = now - inputs.q_time, config.joint_state_timeout
        return f'joint_states stale ({age:.3f} s > {timeout} s)' if age > timeout else ''


def used_bounds(store, known: tuple, lower: np.ndarray, upper: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the bounds a known layout's used positions must lie within (cached per layout).

    Each is its joint's URDF limit widened by ``joint_limit_tolerance``, within
    +-:data:`~grasp_torque_opt.control.checks.MAX_ABS_JOINT_POSITION`: a position
    inside them passes both rules, one outside fails one of them.
    """
    cached = store.joint_bounds
    if cached is not None and cached[0] is known and cached[1] is lower \
            and cached[2] is upper:
        return cached[3], cached[4]
    used = known[2]
    low = np.maximum(lower[used], -MAX_ABS_JOINT_POSITION)
    high = np.minimum(upper[used], MAX_ABS_JOINT_POSITION)
    store.joint_bounds = (known, lower, upper, low, high)
    return low, high


JOINT_STATES = JointStates()
