# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The simulated hand's drivers: how each command interface becomes joint torques.

``grasp-torque-sim --driver NAME`` runs the hand behind one of the node's command
interfaces (docs/node.md, "Command interfaces"); each model turns the last command
received into the joint torque, every physics step, from the encoder's reading q:

- ``effort``: the torque as commanded (the rig adds its joint impedance Kp, Kd around
  the settled configuration, as before: :mod:`~grasp_torque_opt.sim.rig`);
- ``position``: a position servo of stiffness K and damping D, limited in current:
  ``clip(K (q_cmd - q), +-tau_max) - D qdot`` with tau_max = k_t gear I_max (the rig's
  own impedance is off: the servo's stiffness is the joint's);
- ``current``: a current-mode motor: ``k_t gear clip(I, +-I_max)`` (plus the rig's
  impedance, the driver's, as for effort);
- ``hybrid``: a PD with feed-forward, Dex3's motor command:
  ``tau_ff + kp (q_des - q) + kd (dq_des - qdot)`` (the rig's impedance off).

The damping (D, kd) is the rig's Kd, integrated implicitly by MuJoCo. :func:`node_overrides`
gives the node's parameters that match a driver: what ``--with-node`` passes on.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: The drivers, in the order of ``--driver``'s choices (the node's ``command_interface``).
DRIVERS = ('effort', 'position', 'current', 'hybrid')


@dataclass(frozen=True)
class DriverSettings:
    """
    A simulated driver, the same for every joint.

    Attributes:
        kind: one of :data:`DRIVERS`.
        kp: the stiffness [N m/rad]: the rig's impedance (effort, current), the servo's
            K (position), the PD's kp (hybrid).
        kd: the damping [N m s/rad], likewise.
        torque_constant: the motor's k_t [N m/A] (position's current limit, current).
        gear_ratio: joint torque over motor torque [-].
        current_limit: the driver's current limit I_max [A].
    """

    kind: str = 'effort'
    kp: float = 1.0
    kd: float = 0.01
    torque_constant: float = 0.35
    gear_ratio: float = 1.0
    current_limit: float = 2.0

    def __post_init__(self) -> None:
        """Refuse an unknown driver, or a value out of range (naming it)."""
        if self.kind not in DRIVERS:
            raise ValueError(f"driver must be one of {', '.join(DRIVERS)}, got {self.kind!r}")
        for name in ('torque_constant', 'gear_ratio', 'current_limit'):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f'{name} must be finite and > 0, got {value}')
        if self.kind in ('position', 'hybrid') and not self.kp > 0:
            raise ValueError(f'kp must be > 0 for the {self.kind} driver (its stiffness), got '
                             f'{self.kp}')

    @property
    def torque_limit(self) -> float:
        """Give the torque at the current limit, k_t gear I_max [N m]."""
        return self.torque_constant * self.gear_ratio * self.current_limit

    @property
    def rig_impedance(self) -> bool:
        """Whether the rig's own impedance applies (effort, current: the driver's)."""
        return self.kind in ('effort', 'current')


class SimDriver:
    """
    One driver: the last command received, and the joint torque it makes at q.

    Args:
        settings: the driver.
        m: the number of joints.
    """

    def __init__(self, settings: DriverSettings, m: int) -> None:
        self.settings, self.m = settings, m
        #: The last command: values (Float64MultiArray's data, or JointState's effort), and
        #: hybrid's position and velocity (None until one arrives).
        self.values: np.ndarray | None = None
        self.position: np.ndarray | None = None
        self.velocity: np.ndarray | None = None

    def receive(self, values: np.ndarray, position: np.ndarray | None = None,
                velocity: np.ndarray | None = None) -> None:
        """Take a command (hybrid: position and velocity too)."""
        self.values = np.asarray(values, dtype=float)
        if self.settings.kind == 'hybrid':
            self.position = np.asarray(position, dtype=float)
            self.velocity = np.asarray(velocity, dtype=float)

    def torque(self, q: np.ndarray) -> np.ndarray:
        """
        Give the joint torque of the last command at q, damping aside [N m] (zeros before one).

        Hybrid's kd (dq_des - qdot) is kd dq_des here; MuJoCo's damping gives -kd qdot.
        """
        s, values = self.settings, self.values
        if values is None:
            return np.zeros(self.m)
        if s.kind == 'effort':
            return values.copy()
        if s.kind == 'current':
            return s.torque_constant * s.gear_ratio * np.clip(values, -s.current_limit,
                                                              s.current_limit)
        if s.kind == 'position':
            return np.clip(s.kp * (values - q), -s.torque_limit, s.torque_limit)
        return values + s.kp * (self.position - q) + s.kd * self.velocity


def attach(rig, settings: DriverSettings) -> SimDriver:
    """
    Put a driver on a rig (:class:`~grasp_torque_opt.sim.rig.RigSim`): it makes the torques.

    The rig's impedance is turned off for position and hybrid (the servo's stiffness is
    the joint's); its damping stays (the driver's D, kd).
    """
    driver = SimDriver(settings, len(rig.sim.joints))
    rig.driver = driver
    if not settings.rig_impedance:
        rig.kp = 0.0
    return driver


def node_overrides(settings: DriverSettings) -> dict[str, object]:
    """
    Give the node's parameters that match a driver (what ``--with-node`` passes on).

    One value for every joint, as the driver is the same for every joint.
    """
    s = settings
    out: dict[str, object] = {'command_interface': s.kind}
    if s.kind == 'position':
        out['position.stiffness'] = [s.kp]
    elif s.kind == 'current':
        out.update({'current.torque_constant': [s.torque_constant],
                    'current.gear_ratio': [s.gear_ratio],
                    'current.limit': [s.current_limit]})
    elif s.kind == 'hybrid':
        out.update({'hybrid.kp': [s.kp], 'hybrid.kd': [s.kd]})
    return out
