# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The load on the object (geometry_msgs/WrenchStamped), about its origin, in a model frame.

Kept in the given axes; the cycle turns it into base axes at its configuration.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from grasp_torque_opt.control.checks import checked_wrench
from grasp_torque_opt.control.inputs.base import aged
import numpy as np


@dataclass(frozen=True)
class WrenchReading:
    """
    A wrench as plain data.

    Attributes:
        frame: model frame of the axes ('' = the base frame).
        force: force [N], shape (3,).
        torque: moment about the object origin [N m], shape (3,).
    """

    frame: str
    force: Any
    torque: Any


class ExternalWrench:
    """The external_wrench input (:class:`~grasp_torque_opt.control.inputs.base.NodeInput`)."""

    name = 'external_wrench'
    message = 'geometry_msgs/msg/WrenchStamped'
    qos = 'sensor_data'
    counted = True
    enabled = None
    timeout = 'wrench_timeout'
    grasp_only = True

    def check(self, store, reading: WrenchReading) -> tuple[str, np.ndarray]:
        """
        Check the wrench; give (frame, [F, M]).

        Raises:
            InputError: unknown frame, non-finite values, a force or moment norm above
                ``max_wrench_force`` / ``max_wrench_torque``.
        """
        c = store.config
        return reading.frame, checked_wrench(store.setup.hand.model, reading.frame,
                                             reading.force, reading.torque,
                                             c.max_wrench_force, c.max_wrench_torque)

    def keep(self, store, value, now: float) -> dict[str, Any]:
        """Keep the wrench, in its own frame's axes."""
        return {'wrench': value, 'wrench_time': now}

    def stamp_timeout(self, config) -> float:
        """Return wrench_timeout."""
        return config.wrench_timeout

    def stale(self, inputs, config, now: float) -> str:
        """Say that the wrench is older than wrench_timeout (when it is set)."""
        return aged('external_wrench', inputs.wrench_time, config.wrench_timeout, now)


EXTERNAL_WRENCH = ExternalWrench()
