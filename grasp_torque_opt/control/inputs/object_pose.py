# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The object's pose (geometry_msgs/PoseStamped): the contacts from geometry and the load follow it.

In the base frame, a model frame (placed at each cycle's joint state), or any frame tf2
resolves (its transform, looked up by the ROS side at receipt). A pose farther than
``object_pose.max_offset`` from the scenario's at the latest joint state, or farther
than ``uncertainty.pose`` from where the fingertips place the object there
(:class:`~grasp_torque_opt.core.object_from_hand.ObjectFromHand`), is refused; the last
accepted one is used while fresh (``object_pose.timeout``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from grasp_torque_opt.control.geometry import checked_pose, ObjectPose, placements_at, \
    pose_in_base
from grasp_torque_opt.control.inputs.base import latest_q, NO_TF
from grasp_torque_opt.core.exceptions import InputError
import numpy as np


@dataclass(frozen=True)
class PoseReading:
    """
    An object pose as plain data.

    Attributes:
        frame: '' or a model frame, or another with ``transform``.
        position: [m], shape (3,).
        quaternion: (x, y, z, w), shape (4,).
        transform: ``frame``'s rotation and origin in the base frame (tf2), or None.
        unresolved: why ``frame`` could not be looked up (for the message).
    """

    frame: str
    position: Any
    quaternion: Any
    transform: tuple[np.ndarray, np.ndarray] | None = None
    unresolved: str = NO_TF


class ObjectPoseInput:
    """The object_pose input (:class:`~grasp_torque_opt.control.inputs.base.NodeInput`)."""

    name = 'object_pose'
    message = 'geometry_msgs/msg/PoseStamped'
    qos = 'sensor_data'
    counted = False
    enabled = None
    timeout = 'object_pose.timeout'
    grasp_only = True

    def check(self, store, reading: PoseReading) -> ObjectPose:
        """
        Check a pose: its form, then within the bound of the scenario's.

        Raises:
            InputError: not finite, a non-unit quaternion, an unknown frame, no scenario
                object, farther than ``object_pose.max_offset`` from the scenario's pose
                or than ``uncertainty.pose`` from where the fingertips place the object,
                at the latest joint state.
        """
        hand = store.setup.hand
        got = checked_pose(hand, reading.frame, reading.position, reading.quaternion,
                           reading.transform, reading.unresolved)
        if store.scenario_pose is None:
            raise InputError('object_pose', 'the scenario has no object')
        q = latest_q(store)
        if hand.coupling.mimics:
            q = hand.complete(q.copy())
        tips = None if store.hand_object is None else store.hand_object.estimate(q)
        pose_in_base(got, store.scenario_pose, placements_at(hand, q), store.config, tips)
        return got

    def keep(self, store, value: ObjectPose, now: float) -> dict[str, Any]:
        """Keep the pose."""
        return {'object_pose': value, 'object_pose_time': now}

    def stamp_timeout(self, config) -> float:
        """Return object_pose.timeout."""
        return config.object_pose_timeout

    def stale(self, inputs, config, now: float) -> str:
        """Say that the pose is older than object_pose.timeout (when it is set)."""
        t = config.object_pose_timeout
        if inputs.object_pose_time is not None and 0 < t < now - inputs.object_pose_time:
            return f'object_pose stale (older than object_pose.timeout, {t} s)'
        return ''


OBJECT_POSE = ObjectPoseInput()
