# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The base's IMU (sensor_msgs/Imu, with ``imu.enabled``): specific force, angular rate.

In the hand's base frame, or another through its transform (tf2's rotation and origin);
its orientation is not used. ``specific_force`` [m/s^2] reads -g at rest. A reading
:func:`grasp_torque_opt.control.motion.checked_imu` or the cross-checks
(:meth:`~grasp_torque_opt.control.motion.ImuTracker.cross_checked`) refuse is not kept:
the last one ages out by its own timeout (:class:`~grasp_torque_opt.control.motion.ImuTracker`),
then the scenario's gravity is used again; it never makes the inputs stale.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from grasp_torque_opt.control.inputs.base import NO_TF
from grasp_torque_opt.control.motion import checked_imu, Motion
import numpy as np


@dataclass(frozen=True)
class ImuReading:
    """
    An IMU reading as plain data.

    Attributes:
        frame: the IMU's frame ('' or the base frame, else ``transform``'s).
        specific_force: [m/s^2], shape (3,).
        omega: angular velocity [rad/s], shape (3,).
        transform: the IMU frame's rotation and origin in the base frame (None: none).
        unresolved: why ``frame`` could not be looked up (for the message).
    """

    frame: str
    specific_force: Any
    omega: Any
    transform: tuple[np.ndarray, np.ndarray] | None = None
    unresolved: str = NO_TF


class Imu:
    """The imu input (:class:`~grasp_torque_opt.control.inputs.base.NodeInput`)."""

    name = 'imu'
    message = 'sensor_msgs/msg/Imu'
    qos = 'sensor_data'
    counted = False
    enabled = 'imu.enabled'
    timeout = 'imu.timeout_periods, imu.timeout_bounds'
    grasp_only = False

    def check(self, store, reading: ImuReading) -> tuple:
        """
        Check a reading; give (gravity, omega, point, reference direction).

        Its own bounds (:func:`.motion.checked_imu`), then the cross-checks with the
        reading before and with gravity (:meth:`.motion.ImuTracker.cross_checked`).
        """
        c = store.config
        g, w, point = checked_imu(store.setup.hand.base_frame, reading.frame,
                                  reading.specific_force, reading.omega, reading.transform,
                                  reading.unresolved, c)
        gravity = np.asarray(c.gravity if store.inputs.gravity is None
                             else store.inputs.gravity, dtype=float)
        return g, w, point, store.imu.cross_checked(store.now, g, w, gravity, c)

    def keep(self, store, value: tuple, now: float) -> dict[str, Any]:
        """Keep the base's motion: the rate filtered into an angular acceleration."""
        g, w, point, reference = value
        c = store.config
        store.imu.reference = reference
        alpha = store.imu.update(now, w, c.imu_angular_filter, c.imu_timeout_bounds[1])
        timeout = store.imu.timeout(c.imu_timeout_periods, c.imu_timeout_bounds)
        return {'motion': Motion(g, w, alpha, point, timeout), 'motion_time': now}

    def stamp_timeout(self, config) -> float:
        """Return the longest IMU timeout."""
        return config.imu_timeout_bounds[1]

    def stale(self, inputs, config, now: float) -> str:
        """Never stale: an old reading is not used by the cycle (it ages out)."""
        return ''


IMU = Imu()
