# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
``current``: motor currents, I = tau / (k_t gear), for current-mode motors.

For motors commanded in current (PSYONIC Ability's current targets, a Dynamixel in
current mode): the joint torque is k_t gear I, so the command I = tau / (k_t gear) [A]
makes the motor produce the certified tau. A current above the driver's limit
(``current.limit``) would be clipped by the driver, and a clipped torque is not the
certified one: such a command is a fault, not published. std_msgs/Float64MultiArray on
``current_commands`` [A]. Zero torque is zero current.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from grasp_torque_opt.control.commands.base import Command, per_joint
from grasp_torque_opt.core.hand import Hand
import numpy as np


@dataclass(frozen=True)
class CurrentSettings:
    """
    The current interface, per joint, shape (m,) each.

    Attributes:
        torque_constant: k_t [N m/A].
        gear_ratio: joint torque over motor torque [-].
        limit: the driver's current limit [A].
    """

    torque_constant: np.ndarray
    gear_ratio: np.ndarray
    limit: np.ndarray

    @classmethod
    def from_config(cls, config: Any, hand: Hand) -> CurrentSettings:
        """Take ``current.*``; raise InputError naming one if unset or mis-sized."""
        m, joints = hand.m, hand.joints
        return cls(per_joint('current.torque_constant', config.current_torque_constant, m,
                             joints, 'current'),
                   per_joint('current.gear_ratio', config.current_gear_ratio, m, joints,
                             'current'),
                   per_joint('current.limit', config.current_limit, m, joints, 'current'))


class CurrentInterface:
    """Currents that make the certified torque, within the driver's limit."""

    name = 'current'

    def __init__(self, settings: CurrentSettings, hand: Hand) -> None:
        self.settings, self.joints = settings, list(hand.joints)

    def command(self, tau: np.ndarray, q: np.ndarray, limits: np.ndarray
                ) -> tuple[Command | None, str]:
        """Give tau / (k_t gear) [A], or why not (over the current limit)."""
        s = self.settings
        current = tau / (s.torque_constant * s.gear_ratio)
        over = np.abs(current) - s.limit
        if np.any(over > 0):
            k = int(np.argmax(over))
            return None, (f'current: {self.joints[k]} needs {current[k]:.4g} A for '
                          f'{tau[k]:.4g} N m, over current.limit {s.limit[k]:.4g} A (a '
                          'clipped current is not the certified torque)')
        return Command(self.name, current, tau), ''

    def zero(self) -> Command | None:
        """Give zero currents."""
        zero = np.zeros(len(self.joints))
        return Command(self.name, zero, zero.copy())
