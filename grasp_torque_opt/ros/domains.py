# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Private ROS domains: ROS_DOMAIN_ID as a base, the domains above it in a stated range.

A process that starts ROS processes of its own (the test suite, the benchmarks, a
driver's ``--with-node``) under ``ROS_DOMAIN_ID=B`` uses the domains B+1 to B+SPAN
and leaves B itself (the shell's own domain, perhaps a robot's) alone. Two such runs
on one machine stay apart when their bases are at least SPAN apart. Without
ROS_DOMAIN_ID the base is a multiple of SPAN from the process id (0 to 216), so two
runs usually differ. Plain module, no rclpy: the test helpers import it too.
"""

from __future__ import annotations

from collections.abc import Mapping
import os

#: How many domains one run uses above its base.
SPAN = 12
#: The highest domain id Fast DDS's default port mapping allows.
MAX_DOMAIN = 232


def base(environ: Mapping[str, str] = os.environ, pid: int | None = None) -> int:
    """
    Return the base: ROS_DOMAIN_ID, or a multiple of SPAN from the process id.

    Raises:
        ValueError: ROS_DOMAIN_ID is not an integer from 0 to MAX_DOMAIN - SPAN.
    """
    given = environ.get('ROS_DOMAIN_ID', '').strip()
    if given:
        try:
            b = int(given)
        except ValueError:
            raise ValueError(f'ROS_DOMAIN_ID {given!r}: not an integer') from None
        if not 0 <= b <= MAX_DOMAIN - SPAN:
            raise ValueError(f'ROS_DOMAIN_ID {b}: its private domains ROS_DOMAIN_ID + 1 to '
                             f'+ {SPAN} must lie within 0 to {MAX_DOMAIN}; choose 0 to '
                             f'{MAX_DOMAIN - SPAN}')
        return b
    pid = os.getpid() if pid is None else pid
    return SPAN * (pid % ((MAX_DOMAIN - SPAN) // SPAN + 1))


def private(k: int, environ: Mapping[str, str] = os.environ) -> int:
    """Return the ``k``-th private domain of this run (0 first): base + 1 + k mod SPAN."""
    return base(environ) + 1 + k % SPAN
