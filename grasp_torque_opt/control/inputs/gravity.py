# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Gravity (geometry_msgs/Vector3Stamped) [m/s^2]: g(q) and the scenario's load follow it.

In the hand's base frame, or any frame with its rotation (tf2's, looked up by the ROS
side). Once one has arrived it goes stale after ``gravity_timeout``, as the other
inputs do; the gravity in use turns towards a new vector at ``max_gravity_rate``
(:mod:`grasp_torque_opt.control.rates`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from grasp_torque_opt.control.checks import checked_gravity
from grasp_torque_opt.control.inputs.base import aged, NO_TF
from grasp_torque_opt.control.rates import turned_towards
import numpy as np


@dataclass(frozen=True)
class GravityReading:
    """
    A gravity vector as plain data.

    Attributes:
        frame: the frame of the vector: '' or the base frame, or any frame when
            ``rotation`` is given.
        vector: gravity in ``frame`` [m/s^2], shape (3,).
        rotation: base-from-frame rotation, shape (3, 3), when the frame could be looked
            up (tf2); None: ``frame`` must be the base frame.
        unresolved: why ``frame`` could not be looked up (for the message).
    """

    frame: str
    vector: Any
    rotation: np.ndarray | None = None
    unresolved: str = NO_TF


class Gravity:
    """The gravity input (:class:`~grasp_torque_opt.control.inputs.base.NodeInput`)."""

    name = 'gravity'
    message = 'geometry_msgs/msg/Vector3Stamped'
    qos = 'sensor_data'
    counted = False
    enabled = None
    timeout = 'gravity_timeout'
    grasp_only = False

    def check(self, store, reading: GravityReading) -> np.ndarray:
        """
        Check the vector; give it in base axes.

        Raises:
            InputError: another frame without ``rotation``, not finite, a norm above
                :data:`~grasp_torque_opt.control.parameters.limits.MAX_GRAVITY` or outside
                ``gravity_norm_bounds``.
        """
        return checked_gravity(store.setup.hand.base_frame, reading.frame, reading.vector,
                               reading.rotation, reading.unresolved,
                               store.config.gravity_norm_bounds)

    def keep(self, store, value: np.ndarray, now: float) -> dict[str, Any]:
        """Keep the vector, turned from the one in use by at most max_gravity_rate."""
        old, old_time = store.inputs.gravity, store.inputs.gravity_time
        timeout = store.config.gravity_timeout
        if old is not None and not (timeout > 0 and now - old_time > timeout):
            value = turned_towards(old, value, store.config.max_gravity_rate * (now - old_time))
        return {'gravity': value, 'gravity_time': now}

    def stamp_timeout(self, config) -> float:
        """Return gravity_timeout."""
        return config.gravity_timeout

    def stale(self, inputs, config, now: float) -> str:
        """Say that gravity is older than gravity_timeout (when it is set)."""
        return aged('gravity', inputs.gravity_time, config.gravity_timeout, now)


GRAVITY = Gravity()
