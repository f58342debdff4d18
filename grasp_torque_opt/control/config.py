# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The cycle's settings: timing, safety limits, the fault policy, the method."""

from __future__ import annotations

from dataclasses import dataclass

from grasp_torque_opt.core.certificate import DEFAULT_TOLERANCE

#: The fault policies: keep the last certified command, or publish zero torques.
POLICIES = ('hold', 'zero')


@dataclass(frozen=True)
class CycleConfig:
    """
    Timing and safety settings of the cycle.

    Attributes:
        joint_state_timeout: joint states older than this stop commands [s] (> 0).
        contacts_timeout: once contacts have arrived on the topic, older than this
            stop commands [s]; 0 disables the check.
        wrench_timeout: the same for the external wrench [s]; 0 disables it.
        hold_time: how long after the last certified command a fault may last
            before the policy applies [s].
        fault_policy: ``hold`` or ``zero``.
        gravity_compensation: add the fingers' own gravity torques g(q).
        gravity: gravity in the base frame [m/s^2], shape (3,).
        certificate_tolerance: tolerance of the certificate (SI units).
        max_message_bytes: a message whose serialized form is longer than this is
            rejected before it is deserialized [bytes].
        max_joint_state_entries: a joint state with more names or positions than
            this is rejected unread [-].
        max_wrench_force: a load whose force norm exceeds this is rejected [N].
        max_wrench_torque: a load whose moment norm exceeds this is rejected [N m].
        max_contact_distance: a contact point farther than this from the base
            origin (at the cycle's configuration) stops commands [m].
        stamp_future_tolerance: a header stamp more than this ahead of the clock
            is rejected [s].
        cycle_budget: a cycle that takes longer publishes nothing (overrun) [s].
            Its solvers stop by the budget (with joint_state_timeout if smaller).
        method: ``tau-qp`` (the paper's polygon) or ``tau-qp-adaptive`` (the
            exact-cone optimum with certified bounds, docs/adaptive.md; DAQP).
        gravity_timeout: once gravity has arrived on its input, older than this
            stops commands [s]; 0 disables the check.
        compiled: run the cycle compiled (:mod:`grasp_torque_opt.control.compiled`)
            where it applies (tau-qp, sum of squares, ProxSuite, A of full column
            rank), else and on anything it cannot certify the Python cycle; False:
            the Python cycle always.
    """

    joint_state_timeout: float = 0.1
    contacts_timeout: float = 0.5
    wrench_timeout: float = 0.5
    hold_time: float = 0.1
    fault_policy: str = 'hold'
    gravity_compensation: bool = False
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    certificate_tolerance: float = DEFAULT_TOLERANCE
    max_joint_state_entries: int = 256
    max_message_bytes: int = 65536
    max_wrench_force: float = 1000.0
    max_wrench_torque: float = 100.0
    max_contact_distance: float = 1.0
    stamp_future_tolerance: float = 0.5
    cycle_budget: float = 0.05
    method: str = 'tau-qp'
    gravity_timeout: float = 0.5
    compiled: bool = True
