# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The hand's base moving: apparent gravity from an IMU, the object's inertial load, margins.

An accelerometer on the base reads the specific force f = a - g (at rest: -g, "1 g
up"). In the base frame, the object held still in the hand must be given the force
m (a_c - g) by the fingers, so the load they resist is the weight under the apparent
gravity g_app = g - a = -f (in base axes: -R f, R the base-from-IMU rotation), plus the
terms of the base's rotation: the centre c, at r = c - p from the IMU point p,
accelerates by alpha x r + omega x (omega x r) more, and the object's inertia I (about
its centre) needs the moment I alpha + omega x I omega. :func:`motion_wrench` is that
load about the object origin; g(q) of the fingers takes g_app too (their own links'
rotation terms are left out: a first-order rule for the fingers' small masses).

The angular acceleration is the filtered derivative of the IMU's angular velocity
(:class:`ImuTracker`, a first-order low-pass of time constant ``imu.angular_filter``),
and the IMU's freshness follows its measured rate (:meth:`ImuTracker.timeout`).

:func:`uncertainty_margin` turns a stated friction and pose uncertainty into the
friction margin k (docs/node.md, "Margin from stated uncertainty").
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from grasp_torque_opt.control.checks import finite, show
from grasp_torque_opt.control.rates import turned_towards
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.scenario import ObjectSpec
import numpy as np
import pinocchio as pin


@dataclass(frozen=True)
class Motion:
    """
    The base's motion as an IMU gave it, in base axes.

    Attributes:
        gravity: apparent gravity g - a = -R f [m/s^2], shape (3,).
        omega: angular velocity [rad/s], shape (3,).
        alpha: angular acceleration, filtered derivative of ``omega`` [rad/s^2].
        point: the IMU's position in the base frame [m], shape (3,).
        timeout: how long after its receipt this reading is fresh [s].
    """

    gravity: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray
    point: np.ndarray
    timeout: float


def object_inertia(obj: ObjectSpec) -> np.ndarray:
    """
    Return a uniform object's inertia about its centre, base axes [kg m^2], shape (3, 3).

    Solid sphere 2/5 m r^2; box m/12 (b^2 + c^2) about each axis; cylinder (axis z)
    m (3 r^2 + h^2)/12 across and m r^2/2 along; turned by the object's rpy.
    """
    m, s = obj.mass, np.asarray(obj.size, dtype=float)
    if obj.shape == 'sphere':
        local = np.eye(3) * 0.4 * m * s[0] ** 2
    elif obj.shape == 'box':
        x2, y2, z2 = s[:3] ** 2
        local = np.diag([y2 + z2, x2 + z2, x2 + y2]) * m / 12.0
    else:  # cylinder: radius, length
        r2, h2 = s[0] ** 2, s[1] ** 2
        across = m * (3.0 * r2 + h2) / 12.0
        local = np.diag([across, across, 0.5 * m * r2])
    R = pin.rpy.rpyToMatrix(*np.asarray(obj.rpy, dtype=float))
    return R @ local @ R.T


def motion_wrench(obj: ObjectSpec, origin: np.ndarray, motion: Motion) -> np.ndarray:
    """
    Return the object's load on a moving base, about ``origin``, base axes [N, N m].

    The weight under the apparent gravity, less the mass times the acceleration the
    base's rotation gives the centre, and the inertial moment -(I alpha + w x I w).
    """
    c = np.asarray(obj.position, dtype=float)
    r = c - motion.point
    w, alpha = motion.omega, motion.alpha
    force = obj.mass * (motion.gravity - np.cross(alpha, r) - np.cross(w, np.cross(w, r)))
    inertia = object_inertia(obj)
    moment = -(inertia @ alpha + np.cross(w, inertia @ w))
    return np.concatenate((force, moment + np.cross(c - origin, force)))


class ImuTracker:
    """
    The IMU's rate and the filtered derivative of its angular velocity.

    The period is a running mean (weight 0.1) of the time between accepted readings;
    the derivative of the angular velocity is low-passed with time constant ``tau``.
    A gap longer than ``reset_after`` starts both again (the reading after a pause is
    not differentiated across it).
    """

    def __init__(self) -> None:
        """Know nothing yet."""
        self.period: float | None = None
        self._last: tuple[float, np.ndarray] | None = None  # (receipt, omega)
        self.alpha = np.zeros(3)
        #: The reference gravity's direction, base axes (None: gravity's own, until the
        #: first accepted reading), and the last reading seen, refused or not (receipt,
        #: omega): the cross-checks' state (:meth:`cross_checked`).
        self.reference: np.ndarray | None = None
        self._seen: tuple[float, np.ndarray] | None = None
        #: The receipt of the last reading the rate rule refused (None: none yet).
        self._chatter: float | None = None
        #: The mean time between the readings seen, refused or not [s] (a running mean
        #: of weight 0.1; None: not measured).
        self.spacing: float | None = None
        #: Why the last reading was refused by a cross-check ('' when it was accepted).
        self.refused = ''

    def cross_checked(self, now: float, apparent: np.ndarray, omega: np.ndarray,
                      gravity: np.ndarray, config) -> np.ndarray:
        """
        Cross-check a reading with the last one and with gravity; give the new reference.

        Two rules (docs/node.md, "Cross-checks and the one rate rule"):

        - the angular velocity changes no faster than ``imu.max_angular_acceleration``
          since the reading before (refused or not, within ``imu.timeout_bounds``' upper
          bound), and after a reading that does not, the readings are refused until
          they have kept that rule for that upper bound: a chattering rate is refused
          whole, even when lost readings make two in a row agree;
        - the arm's acceleration |g_app - g_ref| is at most ``imu.max_arm_acceleration``,
          g_ref gravity's norm along the reference direction turned towards g_app's by at
          most (|omega| + ``imu.turn_tolerance``) times the time since the reading before:
          gravity turns in the base only as fast as the base turns.

        The time between two readings is their receipts' (as for the derivative the rule
        guards, :meth:`update`), but at least the mean time between the readings seen
        (:attr:`spacing`), up to ``imu.timeout_bounds``' lower bound: readings a
        middleware delivers in a burst are not taken for a jump (the filtered derivative
        weighs such a reading by its short time, too).

        Args:
            now: the reading's receipt [s].
            apparent: its apparent gravity -R f, base axes [m/s^2], shape (3,).
            omega: its angular velocity, base axes [rad/s], shape (3,).
            gravity: the gravity in use without an IMU, base axes [m/s^2], shape (3,).
            config: the ``imu.*`` settings.

        Returns:
            The reference direction to keep when the reading is accepted, shape (3,).

        Raises:
            InputError: either rule fails (the reading is seen: the next is compared
                with it).
        """
        seen, self._seen = self._seen, (now, omega.copy())
        dt = None if seen is None else max(now - seen[0], 0.0)
        if dt is not None and dt > config.imu_timeout_bounds[1]:
            dt = None  # after a pause: nothing to compare with
        elif dt is not None:
            self.spacing = dt if self.spacing is None else self.spacing + 0.1 * (
                dt - self.spacing)
            dt = max(dt, min(self.spacing, config.imu_timeout_bounds[0]))
        try:
            change = 0.0 if dt is None else float(np.linalg.norm(omega - seen[1]))
            settle = config.imu_timeout_bounds[1]
            if dt is not None and change > config.imu_max_angular_acceleration * dt:
                self._chatter = now
                rate = f'{change / dt:.6g} rad/s^2' if dt > 0.0 else f'{change:.6g} rad/s at once'
                raise InputError('imu.angular_velocity', (
                    f'changed at {rate} since the reading before, more than '
                    f'imu.max_angular_acceleration ({config.imu_max_angular_acceleration:g}'
                    ' rad/s^2)'))
            if self._chatter is not None and now - self._chatter < settle:
                raise InputError('imu.angular_velocity', (
                    f'{1e3 * (now - self._chatter):.4g} ms after a reading over '
                    'imu.max_angular_acceleration: refused until the rate has kept it for '
                    f"imu.timeout_bounds' upper bound ({1e3 * settle:g} ms)"))
            dt = dt or 0.0
            norm = float(np.linalg.norm(gravity))
            u = self.reference if self.reference is not None else (
                gravity / norm if norm > 1e-9 else np.array([0.0, 0.0, -1.0]))
            seen_turn = (float(np.linalg.norm(omega)) + config.imu_turn_tolerance) * dt
            a_norm = float(np.linalg.norm(apparent))
            if a_norm > 1e-9:
                u = turned_towards(u, apparent / a_norm, seen_turn)
                u = u / np.linalg.norm(u)
            arm = float(np.linalg.norm(apparent - norm * u))
            if arm > config.imu_max_arm_acceleration:
                raise InputError('imu.linear_acceleration', (
                    f'says the arm accelerates {arm:.6g} m/s^2 ({arm / 9.80665:.3g} g) from '
                    "gravity as the IMU's own rotation lets it have turned, more than "
                    f'imu.max_arm_acceleration ({config.imu_max_arm_acceleration:g} m/s^2)'))
        except InputError as e:
            self.refused = str(e)
            raise
        self.refused = ''
        return u

    def update(self, now: float, omega: np.ndarray, tau: float, reset_after: float
               ) -> np.ndarray:
        """Take a reading's angular velocity (base axes); give the filtered derivative."""
        last = self._last
        self._last = (now, omega.copy())
        if last is None or not 0.0 < now - last[0] <= reset_after:
            self.alpha = np.zeros(3)
            return self.alpha
        dt = now - last[0]
        self.period = dt if self.period is None else self.period + 0.1 * (dt - self.period)
        raw = (omega - last[1]) / dt
        self.alpha = self.alpha + dt / (tau + dt) * (raw - self.alpha)
        return self.alpha

    def timeout(self, periods: float, bounds: tuple[float, float]) -> float:
        """
        How long a reading stays fresh [s]: ``periods`` measured periods, within ``bounds``.

        Before a period is measured: the upper bound.
        """
        low, high = bounds
        if self.period is None:
            return high
        return min(max(periods * self.period, low), high)


def tilt_radius(obj: ObjectSpec | None, tip_radius: float) -> float:
    """
    Return R + r, the sum of the object's and the tip's curvature radii [m] (inf: flat).

    A pose error delta of a round tip on a curved surface tilts the contact normal by
    delta / (R + r); on a flat face (a box) it does not tilt it (inf).

    Raises:
        InputError: no object in the scenario (its radius is not known).
    """
    if obj is None:
        raise InputError('uncertainty.pose', "needs the scenario's object (its radius)")
    if obj.shape == 'box':
        return math.inf
    return float(obj.size[0]) + tip_radius


def uncertainty_margin(mu: float, friction: float, pose: float, radius_sum: float) -> float:
    """
    Return the friction margin k for a stated friction and pose uncertainty.

    The friction cone's half-angle atan(mu (1 - friction)) narrowed by the normal's tilt
    pose / radius_sum gives mu_eff = tan(atan(mu (1 - friction)) - tilt); the margin is
    the node's k, planning in the cone mu / (1 + k): k = mu / mu_eff - 1.

    Args:
        mu: the tangential friction coefficient.
        friction: the friction uncertainty, a fraction in [0, 1).
        pose: the contact position / object pose uncertainty [m].
        radius_sum: R + r [m] (:func:`tilt_radius`).

    Raises:
        InputError: the stated uncertainty leaves no friction (mu_eff <= 0).
    """
    tilt = pose / radius_sum if math.isfinite(radius_sum) else 0.0
    angle = math.atan(mu * (1.0 - friction)) - tilt
    if angle <= 0.0:
        raise InputError('uncertainty', f'friction {friction:g} and pose {1e3 * pose:g} mm '
                         f'(a tilt of {math.degrees(tilt):.3g} deg) leave no friction of mu '
                         f'{mu:g}: the grasp cannot be planned to hold')
    return mu / math.tan(angle) - 1.0


def checked_imu(base: str, frame: str, specific_force: np.ndarray, omega: np.ndarray,
                transform: tuple[np.ndarray, np.ndarray] | None, unresolved: str, config
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Check an IMU reading; return the apparent gravity, the angular velocity, the IMU point.

    All in the base frame: g_app = -R f, omega_base = R omega, the IMU frame's origin.

    Raises:
        InputError: another frame without ``transform``, not finite, a norm above
            ``imu.max_specific_force`` or ``imu.max_angular_velocity``.
    """
    if frame not in ('', base) and transform is None:
        raise InputError('imu.header.frame_id', f"'{show(frame)}' is not the hand's base "
                         f"frame '{base}' (nor empty), and cannot be transformed "
                         f'({unresolved})')
    f = finite(specific_force, 'imu.linear_acceleration')
    w = finite(omega, 'imu.angular_velocity')
    for v, name, bound, unit, key in (
            (f, 'linear_acceleration', config.imu_max_specific_force, 'm/s^2',
             'imu.max_specific_force'),
            (w, 'angular_velocity', config.imu_max_angular_velocity, 'rad/s',
             'imu.max_angular_velocity')):
        if v.shape != (3,):
            raise InputError(f'imu.{name}', f'{v.size} values, expected 3')
        with np.errstate(over='ignore'):
            norm = float(np.linalg.norm(v))
        if norm > bound:
            raise InputError(f'imu.{name}', f'norm {norm:.6g} {unit} exceeds {key} '
                             f'({bound:g} {unit})')
    R, point = (np.eye(3), np.zeros(3)) if transform is None else (
        finite(transform[0], 'imu.header.frame_id transform'),
        finite(transform[1], 'imu.header.frame_id transform'))
    return -(R @ f), R @ w, point


def efforts_of(names: list[str], efforts: list[float] | None, joints: list[str],
               index: tuple | None) -> tuple[np.ndarray | None, str, tuple | None]:
    """
    Return the actuators' measured efforts of a joint state, or None and why not.

    Args:
        names: the joint state's names.
        efforts: its efforts (may be empty).
        joints: the actuated joints in command order.
        index: the cache of the last call ((names, indices)), or None.

    Returns:
        (efforts in command order or None, why not ('' if given), the cache).
    """
    if efforts is None or len(efforts) == 0:
        return None, 'joint_states.effort is empty (the driver reports no effort)', index
    if len(efforts) != len(names):
        return None, (f'joint_states.effort has {len(efforts)} values for {len(names)} '
                      'names'), index
    if index is None or index[0] != names:
        lookup = {n: i for i, n in enumerate(names)}
        index = (list(names), np.array([lookup[j] for j in joints]))
    e = np.asarray(efforts, dtype=float)[index[1]]
    if not np.all(np.isfinite(e)):
        k = int(np.argmin(np.isfinite(e)))
        return None, f'joint_states.effort of {joints[k]} is not finite', index
    return e, '', index
