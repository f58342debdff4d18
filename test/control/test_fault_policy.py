# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The fault policy alone: hold within hold_time, then hold or zero; recoveries; limits."""

import dataclasses

from grasp_torque_opt.control.fault_policy import CycleResult, FaultPolicy
from grasp_torque_opt.control.inputs.store import Counters
from grasp_torque_opt.control.parameters.generated import CycleConfig
import numpy as np
import pytest


def certified(setup):
    return CycleResult(0.5 * setup.hand.torque_limits, 'solution')


@pytest.mark.parametrize('policy', ['hold', 'zero'])
def test_a_fault_holds_then_the_policy_applies(planar, policy):
    p = FaultPolicy(planar, CycleConfig(hold_time=0.1, fault_policy=policy), Counters())
    p.committed(certified(planar), 0.0, from_fallback=False)
    held = p.faulted(0.05, 'stale')
    assert held.kind == 'none' and held.command is None and p.fault == 'stale'
    late = p.faulted(0.2, 'still stale')
    if policy == 'zero':
        assert late.kind == 'zero' and not late.command.any()
        assert p.in_force is late.command and p.counters.zero_commands == 1
    else:
        assert late.kind == 'none' and p.in_force is p.last_command
    assert p.counters.faults == 1 and p.last is late


def test_never_commanded_zero_policy_applies_at_once(planar):
    p = FaultPolicy(planar, CycleConfig(fault_policy='zero'), Counters())
    assert p.faulted(0.0, 'no joint state yet').kind == 'zero'


def test_a_certified_command_ends_a_fault_and_counts(planar):
    p = FaultPolicy(planar, CycleConfig(), Counters())
    p.faulted(0.0, 'x')
    result = certified(planar)
    p.committed(result, 1.0, from_fallback=True)
    c = p.counters
    assert p.fault == '' and c.recoveries == 1 and c.commands == 1 and c.fallback_solves == 1
    assert p.last_command is result.command and p.last_command_time == 1.0
    assert p.in_force is result.command and p.last is result


def test_reconfigured_zeroes_a_command_over_the_new_limits(planar):
    p = FaultPolicy(planar, CycleConfig(fault_policy='hold'), Counters())
    p.committed(certified(planar), 0.0, from_fallback=False)
    assert p.reconfigured(None, 'stale') is None  # within the limits: nothing new
    p.setup = dataclasses.replace(planar, hand=dataclasses.replace(
        planar.hand, torque_limits=0.1 * planar.hand.torque_limits))
    zero = p.reconfigured(None, 'joint_states stale')
    assert zero.kind == 'zero' and not np.any(zero.command)
    assert zero.fault == 'the command in force exceeds the new torque_limits ' \
        '(joint_states stale)'
