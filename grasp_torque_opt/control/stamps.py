# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The header stamp rule of the input store (docs/node.md, "Input checks").

A base of :class:`~grasp_torque_opt.control.inputs.InputStore`: the stamp marks per
source, checked and kept.
"""

from __future__ import annotations

import math

from grasp_torque_opt.control.parameters import CycleConfig
from grasp_torque_opt.core.exceptions import InputError


class StampRule:
    """The stamp marks of the input sources (``_stamps``: source -> (stamp, receipt))."""

    config: CycleConfig
    _stamps: dict[str, tuple[float, float]]

    def _check_stamp(self, source: str, stamp: float, clock: float | None, now: float) -> None:
        """
        Apply the header stamp rule (docs/node.md, "Input checks").

        0 is an unstamped message: accepted, not compared. A stamp more than
        ``stamp_future_tolerance`` ahead of ``clock`` (when the clock runs, > 0)
        is rejected. A stamp before the topic's mark is rejected (out of order),
        unless the mark is itself stale by receipt time: a restarted publisher
        or a rewound clock recovers after the topic's timeout. The mark is the
        last accepted stamp, but never later than the clock when that message
        was accepted (:meth:`_keep_stamp`): a source stamping ahead of the clock,
        by a fast clock or a lie, cannot push it into the future and lock out a
        source whose stamps agree with the clock.
        """
        if stamp == 0.0:
            return
        if not math.isfinite(stamp) or stamp < 0.0:
            raise InputError(f'{source}.header.stamp', f'is negative ({stamp:.9g} s)')
        tol = self.config.stamp_future_tolerance
        if clock is not None and clock > 0.0 and stamp > clock + tol:
            raise InputError(f'{source}.header.stamp', f'is {stamp - clock:.3f} s ahead of the '
                             f'clock (stamp_future_tolerance {tol} s)')
        last = self._stamps.get(source)
        if last is not None and stamp < last[0] and now - last[1] <= self._timeout(source):
            raise InputError(f'{source}.header.stamp', f'goes backwards by '
                             f'{last[0] - stamp:.6f} s (out of order)')

    def _timeout(self, source: str) -> float:
        """Return how long a source's stamp mark holds [s] (no timeout: joint_state_timeout)."""
        c = self.config
        t = {'joint_states': c.joint_state_timeout, 'contacts': c.contacts_timeout,
             'external_wrench': c.wrench_timeout, 'gravity': c.gravity_timeout,
             'imu': c.imu_timeout_bounds[1]}[source]
        return t if t > 0 else c.joint_state_timeout

    def _keep_stamp(self, source: str, stamp: float, now: float, clock: float | None) -> None:
        """Mark an accepted stamp, never later than the clock (:meth:`_check_stamp`)."""
        if stamp != 0.0:
            mark = min(stamp, clock) if clock is not None and clock > 0.0 else stamp
            self._stamps[source] = (mark, now)
