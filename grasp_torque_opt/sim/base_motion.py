# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The hand's base moving: its extra acceleration as apparent gravity, and a palm IMU.

The simulation stays in the base frame. A base that translates without rotating,
with acceleration a(t) in base axes, is a frame in which every body moves as in an
inertial frame under the apparent gravity g - a(t) (no Coriolis or centrifugal
term without rotation). So :class:`BaseMotion` moves the base by setting MuJoCo's
gravity to g - a(t) at every step: exact for translation, and the joint positions,
the contacts and the object's drift stay in the hand's own frame, as a real hand
sees them. A rotating base is not simulated (the IMU's angular velocity is zero).

An IMU on the base measures the specific force a - g (at rest, palm down with
gravity along base +x: [-9.81, 0, 0], the "1 g up" an accelerometer reads) and the
angular velocity: :func:`imu_reading` takes both from MuJoCo's own kinematics of
the base body, as MuJoCo's accelerometer and gyro sensors do.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np

#: One g [m/s^2] (standard gravity): the unit of ``--base-shake``'s amplitude.
STANDARD_GRAVITY = 9.80665


@dataclass(frozen=True)
class BaseMotion:
    """
    The base's acceleration beyond rest, from the release of the object on.

    Attributes:
        accel: static extra acceleration, base axes [m/s^2], shape (3,).
        shake_amplitude: peak acceleration of a sinusoidal motion [m/s^2].
        shake_frequency: its frequency [Hz].
        shake_axis: its direction, a unit vector in base axes, shape (3,).
    """

    accel: np.ndarray = field(default_factory=lambda: np.zeros(3))
    shake_amplitude: float = 0.0
    shake_frequency: float = 0.0
    shake_axis: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))

    def __post_init__(self) -> None:
        """Check the values: finite, a unit axis, a non-negative amplitude and frequency."""
        accel, axis = np.asarray(self.accel, dtype=float), np.asarray(self.shake_axis, float)
        if accel.shape != (3,) or not np.all(np.isfinite(accel)):
            raise ValueError(f'accel must be 3 finite values [m/s^2], got {self.accel}')
        if axis.shape != (3,) or abs(np.linalg.norm(axis) - 1.0) > 1e-9:
            raise ValueError(f'shake_axis must be a unit vector, got {self.shake_axis}')
        for name in ('shake_amplitude', 'shake_frequency'):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f'{name} must be finite and >= 0, got {value}')
        object.__setattr__(self, 'accel', accel)
        object.__setattr__(self, 'shake_axis', axis)

    @property
    def moving(self) -> bool:
        """Return whether the base accelerates at all."""
        return bool(np.any(self.accel) or self.shake_amplitude > 0)

    def acceleration(self, t: float) -> np.ndarray:
        """
        Return the base's acceleration at ``t`` seconds after release, base axes [m/s^2].

        The shake is a(t) = A sin(2 pi f t) along its axis (a base oscillating about
        a point, its velocity -A/(2 pi f) cos(2 pi f t)); zero before release (t < 0).
        """
        if t < 0:
            return np.zeros(3)
        shake = self.shake_amplitude * np.sin(2 * np.pi * self.shake_frequency * t)
        return self.accel + shake * self.shake_axis

    def apparent_gravity(self, gravity: np.ndarray, t: float) -> np.ndarray:
        """Return g - a(t): gravity as the accelerating base feels it, base axes [m/s^2]."""
        return np.asarray(gravity, dtype=float) - self.acceleration(t)


def imu_reading(model: mujoco.MjModel, data: mujoco.MjData, body: int
                ) -> tuple[np.ndarray, np.ndarray]:
    """
    Read an IMU at a body's origin: specific force [m/s^2] and angular velocity [rad/s].

    Both in the body's own axes (its link frame, MuJoCo's mjOBJ_XBODY: not the frame of
    its principal axes of inertia, mjOBJ_BODY, which a palm inside a robot turns away
    from its link's), from MuJoCo's kinematics at the current state and gravity
    (MuJoCo counts gravity as the world accelerating up, so a body at rest reads
    -gravity, as an accelerometer does).
    """
    mujoco.mj_rnePostConstraint(model, data)
    acc, vel = np.zeros(6), np.zeros(6)
    mujoco.mj_objectAcceleration(model, data, mujoco.mjtObj.mjOBJ_XBODY, body, acc, 1)
    mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_XBODY, body, vel, 1)
    return acc[3:].copy(), vel[:3].copy()
