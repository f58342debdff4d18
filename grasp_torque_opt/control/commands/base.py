# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
What every command interface shares: the command, the protocol, per-joint settings.

A :class:`Command` carries the values a driver takes, in its units, and the torque the
driver produces from them at the configuration the node measured (the certified one).
Position-like interfaces (``position``, ``hybrid``) command around a held reference
q_hold (:class:`HeldReference`): the measured joint positions of the joint state that the
first certified command answered, kept while the node commands.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

from grasp_torque_opt.core.exceptions import InputError
import numpy as np


@dataclass(frozen=True)
class Command:
    """
    One command in a driver's units: what the node publishes.

    Attributes:
        interface: the interface's name (``command_interface``).
        values: the Float64MultiArray's data, one per joint in ``joints`` order: torques
            [N m] (effort), positions [rad] (position), currents [A] (current), or the
            feed-forward torques [N m] (hybrid: JointState's effort).
        torque: the torque the driver produces from it at the measured configuration,
            the certified one [N m], shape (m,).
        position: hybrid: the PD's target position q_hold [rad] (None otherwise).
        velocity: hybrid: the PD's target velocity, zeros [rad/s] (None otherwise).
    """

    interface: str
    values: np.ndarray
    torque: np.ndarray
    position: np.ndarray | None = None
    velocity: np.ndarray | None = None

    def well_formed(self, m: int, checked: np.ndarray | None = None) -> bool:
        """
        Whether every array has m finite entries (the node's promise on each message).

        ``checked``: an array the caller has just checked so (the certified torque,
        which an effort command's values and torque are): not checked again.
        """
        for a in (self.values, self.torque, self.position, self.velocity):
            if a is None or a is checked:
                continue
            if a.shape != (m,) or not np.isfinite(a).all():
                return False
        return True


class CommandInterface(Protocol):
    """
    A command interface: the certified torque to a driver's command, or a refusal.

    Attributes:
        name: its ``command_interface`` name.
    """

    name: str

    def command(self, tau: np.ndarray, q: np.ndarray, limits: np.ndarray
                ) -> tuple[Command | None, str]:
        """
        Give the command that makes the driver produce ``tau`` at ``q``, or why none.

        Args:
            tau: the certified torque, ``joints`` order [N m], shape (m,).
            q: the measured positions of the commanded joints [rad], shape (m,).
            limits: the torque limits in force [N m], shape (m,).

        Returns:
            (the command, '') or (None, the fault's reason).
        """

    def zero(self) -> Command | None:
        """Give the command of zero torque (None: none can be made yet)."""


def per_joint(name: str, value: Sequence[float] | None, m: int, joints: Sequence[str],
              required_by: str) -> np.ndarray:
    """
    Expand one value for every joint, or one per joint, to shape (m,).

    Raises:
        InputError: naming ``name``: unset, or neither 1 nor m entries.
    """
    if value is None or len(value) == 0:
        raise InputError(name, f'must be set for command_interface {required_by} (one value '
                         f'for every joint, or one per joint: {m})')
    a = np.asarray(value, dtype=float)
    if a.shape not in ((1,), (m,)):
        raise InputError(name, f'must have 1 entry or one per joint ({m}: '
                         f"{', '.join(joints)}), got {a.size}")
    return np.broadcast_to(a, (m,)).copy()


class HeldReference:
    """
    q_hold: the measured positions the first certified command answered, then kept.

    The servo's torque at the measured q is ``tau + K (q_hold - q)``: tau itself at
    q_hold, and away from it the joint impedance the driver page asks every driver to
    keep (docs/driver.md), of stiffness K.
    """

    def __init__(self, stiffness: np.ndarray, joints: Sequence[str]) -> None:
        self.stiffness, self.joints = stiffness, list(joints)
        #: The held reference [rad] (None until the first certified command).
        self.q_hold: np.ndarray | None = None

    def at(self, tau: np.ndarray, q: np.ndarray, limits: np.ndarray, what: str
           ) -> tuple[np.ndarray | None, str]:
        """
        Give q_hold (taken now if unset) if the servo's torque at q is within the limits.

        Returns:
            (q_hold, '') or (None, why): the servo would produce more than torque_limits.
        """
        held = q.copy() if self.q_hold is None else self.q_hold
        servo = tau + self.stiffness * (held - q)
        over = np.abs(servo) - limits
        if not np.all(np.isfinite(servo)) or np.any(over > 0):
            k = int(np.argmax(np.where(np.isfinite(over), over, np.inf)))
            return None, (f'{what}: the driver would produce {servo[k]:.4g} N m at '
                          f'{self.joints[k]} (tau {tau[k]:.4g} N m + its stiffness times '
                          f'q_hold - q), over torque_limits {limits[k]:.4g} N m')
        self.q_hold = held
        return held, ''
