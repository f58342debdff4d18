# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
SIGINT and SIGTERM as a flag that the spin loop and long waits poll.

Only a flag: an exception raised in a handler would surface at whatever bytecode the
main thread runs next -- inside rclpy's executor (between a handle's ``__enter__`` and
its exit), inside the events executor's C++ callback loop, or inside a ``__del__``,
where Python drops it and the node spins on. A second signal raises
KeyboardInterrupt (a way out should the stop itself hang).
"""

from __future__ import annotations

import signal
from typing import Any

#: Signal that asked the runner to stop (None: none yet).
_stop_signal: int | None = None


def stop_requested() -> bool:
    """Say whether a stop signal has arrived (polled by waits that may take long)."""
    return _stop_signal is not None


def interrupt(signum: int, frame: Any) -> None:
    """Ask the spin loop to end on SIGINT/SIGTERM; the node then stops cleanly."""
    global _stop_signal
    if _stop_signal is not None:
        raise KeyboardInterrupt
    _stop_signal = signum


def install() -> dict[int, Any]:
    """Clear the flag and handle SIGINT and SIGTERM; give the handlers replaced."""
    global _stop_signal
    _stop_signal = None
    # SIGINT explicitly too: a process started from a background job inherits it ignored.
    return {sig: signal.signal(sig, interrupt) for sig in (signal.SIGINT, signal.SIGTERM)}


def restore(previous: dict[int, Any]) -> None:
    """Put back the handlers :func:`install` replaced."""
    for sig, handler in previous.items():
        signal.signal(sig, handler)
