# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
``position``: position targets for a servo of stated stiffness, q_cmd = q_hold + tau / K.

For current-limited position servos (LEAP's Dynamixels, Allegro V4's position interface):
the servo produces K (q_cmd - q) [N m] (its P gain as a joint stiffness), so the command
q_cmd = q_hold + tau / K makes it produce ``tau + K (q_hold - q)``: the certified tau at
the held reference q_hold (:class:`~.base.HeldReference`), and away from it the joint
impedance of stiffness K that the driver page asks of every driver. The servo's torque at
the measured q must be within ``torque_limits`` (set them at or below the torque of the
servo's current limit) and q_cmd within the joint's URDF position limits (a servo would
stop there): else a fault, never a clip. std_msgs/Float64MultiArray on
``position_commands`` [rad] (``position_controllers/JointGroupPositionController``).
Zero torque is q_hold itself.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from grasp_torque_opt.control.commands.base import Command, HeldReference, per_joint
from grasp_torque_opt.core.hand import Hand
import numpy as np


@dataclass(frozen=True)
class PositionSettings:
    """
    The position interface.

    Attributes:
        stiffness: the servo's stiffness K per joint [N m/rad], shape (m,).
    """

    stiffness: np.ndarray

    @classmethod
    def from_config(cls, config: Any, hand: Hand) -> PositionSettings:
        """Take ``position.stiffness``; raise InputError naming it if unset or mis-sized."""
        return cls(per_joint('position.stiffness', config.position_stiffness, hand.m,
                             hand.joints, 'position'))


class PositionInterface:
    """Position targets around the held reference."""

    name = 'position'

    def __init__(self, settings: PositionSettings, hand: Hand) -> None:
        self.settings = settings
        self.held = HeldReference(settings.stiffness, hand.joints)
        model = hand.model
        self.lower = np.asarray(model.lowerPositionLimit, dtype=float)[hand.idx_q]
        self.upper = np.asarray(model.upperPositionLimit, dtype=float)[hand.idx_q]
        self.joints = list(hand.joints)

    def command(self, tau: np.ndarray, q: np.ndarray, limits: np.ndarray
                ) -> tuple[Command | None, str]:
        """Give q_hold + tau / K, or why not (the servo's torque or q_cmd out of limits)."""
        K = self.settings.stiffness
        held = self.held.q_hold if self.held.q_hold is not None else q
        q_cmd = held + tau / K
        outside = (q_cmd < self.lower) | (q_cmd > self.upper)
        if np.any(outside):
            k = int(np.argmax(outside))
            return None, (f'position: q_cmd {q_cmd[k]:.4g} rad at {self.joints[k]} is outside '
                          f'its position limits [{self.lower[k]:.4g}, {self.upper[k]:.4g}] '
                          'rad')
        held, why = self.held.at(tau, q, limits, 'position')
        if held is None:
            return None, why
        return Command(self.name, q_cmd, tau), ''

    def zero(self) -> Command | None:
        """Give q_hold (zero torque there); None before the first certified command."""
        held = self.held.q_hold
        if held is None:
            return None
        return Command(self.name, held.copy(), np.zeros_like(held))
