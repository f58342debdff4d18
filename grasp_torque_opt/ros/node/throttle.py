# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
A log line at most once a period, decided before rclpy's logger is called.

rclpy's ``throttle_duration_sec`` is decided inside its logger, after it has looked up
the caller's frame and source line (``inspect``): tens of microseconds on every call,
also for the lines it then drops. On the joint state's path a fault or a rejection
repeats up to a thousand times a second, so the node asks a :class:`Throttle` first.
"""

from __future__ import annotations

import time


class Throttle:
    """Say when a line is due: the first time, then once ``period`` has passed."""

    def __init__(self, period: float) -> None:
        """Let a line through every ``period`` seconds (monotonic clock)."""
        self.period = period
        self._last: float | None = None

    def due(self) -> bool:
        """Tell whether a line may be logged now (and count it as logged)."""
        now = time.monotonic()
        if self._last is not None and now - self._last < self.period:
            return False
        self._last = now
        return True
