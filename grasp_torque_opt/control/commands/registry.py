# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The command interfaces by name (:data:`REGISTRY`), as the backends' REGISTRY lists solvers.

Each entry: the interface's class, its settings type (made from the node's parameters
by ``from_config``), and what it publishes: the topic, the message (``array``:
std_msgs/Float64MultiArray of ``Command.values``; ``joint_state``:
sensor_msgs/JointState with position, velocity and effort) and the values' unit.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from grasp_torque_opt.control.commands.base import CommandInterface
from grasp_torque_opt.control.commands.current import CurrentInterface, CurrentSettings
from grasp_torque_opt.control.commands.effort import EffortInterface, EffortSettings
from grasp_torque_opt.control.commands.hybrid import HybridInterface, HybridSettings
from grasp_torque_opt.control.commands.position import PositionInterface, PositionSettings
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.hand import Hand


@dataclass(frozen=True)
class Entry:
    """
    One command interface.

    Attributes:
        cls: the interface's class.
        settings: its settings type (``from_config(config, hand)``).
        topic: the topic it publishes on.
        message: ``array`` (Float64MultiArray) or ``joint_state`` (JointState).
        unit: the unit of ``Command.values``.
    """

    cls: type
    settings: type
    topic: str
    message: str
    unit: str


#: Interface name -> its entry; the first is the default.
REGISTRY: dict[str, Entry] = {
    'effort': Entry(EffortInterface, EffortSettings, 'effort_commands', 'array', 'N m'),
    'position': Entry(PositionInterface, PositionSettings, 'position_commands', 'array',
                      'rad'),
    'current': Entry(CurrentInterface, CurrentSettings, 'current_commands', 'array', 'A'),
    'hybrid': Entry(HybridInterface, HybridSettings, 'hybrid_commands', 'joint_state',
                    'N m'),
}
#: The ``command_interface`` parameter's choices.
COMMAND_INTERFACES = tuple(REGISTRY)


def make_interface(config: Any, hand: Hand) -> CommandInterface:
    """
    Make the interface ``config.command_interface`` names, with its settings.

    Raises:
        InputError: an unknown interface, or its settings unset or mis-sized (naming the
            parameter).
    """
    name = config.command_interface
    if name not in REGISTRY:
        raise InputError('command_interface', f"must be one of {', '.join(REGISTRY)}, got "
                         f'{name!r}')
    entry = REGISTRY[name]
    return entry.cls(entry.settings.from_config(config, hand), hand)
