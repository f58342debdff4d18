# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
``hybrid``: the certified torque as feed-forward beside a PD, as Unitree's Dex3 takes it.

A hybrid driver produces ``tau_ff + kp (q_des - q) + kd (dq_des - dq)`` per motor (Dex3's
HandCmd_: q, dq, tau, kp, kd). The node sends tau_ff = tau, q_des = q_hold (the held
reference, :class:`~.base.HeldReference`) and dq_des = 0, as sensor_msgs/JointState on
``hybrid_commands`` (name, position, velocity, effort); the driver applies ``hybrid.kp``
and ``hybrid.kd``, which it must share with the node. At rest at q_hold the driver
produces tau, the certified torque; away from it, the joint impedance kp, kd. Its torque
at the measured q (at rest) must be within ``torque_limits``, else a fault. Zero torque
is tau_ff = 0 at q_hold.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from grasp_torque_opt.control.commands.base import Command, HeldReference, per_joint
from grasp_torque_opt.core.hand import Hand
import numpy as np


@dataclass(frozen=True)
class HybridSettings:
    """
    The hybrid interface, per joint, shape (m,) each.

    Attributes:
        kp: the PD's stiffness [N m/rad].
        kd: the PD's damping [N m s/rad].
    """

    kp: np.ndarray
    kd: np.ndarray

    @classmethod
    def from_config(cls, config: Any, hand: Hand) -> HybridSettings:
        """Take ``hybrid.kp`` and ``hybrid.kd``; raise InputError naming one if unset."""
        return cls(per_joint('hybrid.kp', config.hybrid_kp, hand.m, hand.joints, 'hybrid'),
                   per_joint('hybrid.kd', config.hybrid_kd, hand.m, hand.joints, 'hybrid'))


class HybridInterface:
    """Feed-forward torque, the held reference, zero velocity."""

    name = 'hybrid'

    def __init__(self, settings: HybridSettings, hand: Hand) -> None:
        self.settings = settings
        self.held = HeldReference(settings.kp, hand.joints)

    def command(self, tau: np.ndarray, q: np.ndarray, limits: np.ndarray
                ) -> tuple[Command | None, str]:
        """Give (q_hold, 0, tau), or why not (the driver's torque over the limits)."""
        held, why = self.held.at(tau, q, limits, 'hybrid')
        if held is None:
            return None, why
        return Command(self.name, tau, tau, held.copy(), np.zeros_like(tau)), ''

    def zero(self) -> Command | None:
        """Give tau_ff = 0 at q_hold; None before the first certified command."""
        held = self.held.q_hold
        if held is None:
            return None
        zero = np.zeros_like(held)
        return Command(self.name, zero, zero.copy(), held.copy(), zero.copy())
