# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
``effort``: the certified torques themselves, for a ros2_control effort controller.

The node's first interface and its default: std_msgs/Float64MultiArray on
``effort_commands``, one torque per joint [N m]
(``effort_controllers/JointGroupEffortController``). Zero torque is zeros.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from grasp_torque_opt.control.commands.base import Command
from grasp_torque_opt.core.hand import Hand
import numpy as np


@dataclass(frozen=True)
class EffortSettings:
    """The effort interface: nothing beyond the torque limits (the gate's)."""

    @classmethod
    def from_config(cls, config: Any, hand: Hand) -> EffortSettings:
        """Take nothing from the parameters."""
        return cls()


class EffortInterface:
    """The torque is the command."""

    name = 'effort'

    def __init__(self, settings: EffortSettings, hand: Hand) -> None:
        self.settings, self.m = settings, hand.m

    def command(self, tau: np.ndarray, q: np.ndarray, limits: np.ndarray
                ) -> tuple[Command | None, str]:
        """Give tau as it is."""
        return Command(self.name, tau, tau), ''

    def zero(self) -> Command | None:
        """Give zero torques."""
        zero = np.zeros(self.m)
        return Command(self.name, zero, zero)
