# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The cycle's solve alone: an attempt never raises, the rounds' DAQP settings."""

import dataclasses
import time

from cycle_inputs import Injected
from grasp_torque_opt.backends import DaqpSettings, make_solver, ProxSuiteSettings
from grasp_torque_opt.control.cycle import Cycle, round_settings
from grasp_torque_opt.control.inputs.store import Counters, Inputs
from grasp_torque_opt.control.parameters.generated import CycleConfig
import pytest


def cycle(setup, solver, **config):
    own = dataclasses.replace(setup, hand=dataclasses.replace(setup.hand))
    return Cycle(own, CycleConfig(cycle_budget=10.0, **config), Counters(), solver)


def test_rounds_take_the_backends_tolerance_as_make_solver_maps_it():
    prox = ProxSuiteSettings(eps_abs=1e-7, max_iter=70)
    expected = DaqpSettings(primal_tol=1e-7, iter_limit=70)
    assert round_settings(make_solver('proxsuite', prox)) == expected
    assert round_settings(make_solver('daqp', prox)) == expected
    assert round_settings(make_solver('quadprog', prox)) == DaqpSettings()
    assert round_settings(Injected('nan-x')) == DaqpSettings()


def test_an_attempt_is_a_certified_command_or_a_reason(planar):
    c = cycle(planar, make_solver('proxsuite'), compiled=False)
    inputs = Inputs(q=planar.q, q_time=0.0)
    ok = c.attempt(inputs, time.perf_counter() + 10.0)
    assert ok.kind == 'solution' and ok.solution.optimal and ok.fault == ''


@pytest.mark.parametrize('mode, reason', [('raise-solver', 'solver failed: '),
                                          ('raise-other', 'cycle failed: ZeroDivisionError'),
                                          ('wrong-x', 'no certified solution')])
def test_a_failed_attempt_never_raises_and_counts(planar, mode, reason):
    c = cycle(planar, Injected(mode), compiled=False)
    result = c.attempt(Inputs(q=planar.q, q_time=0.0), time.perf_counter() + 10.0)
    assert result.kind == 'none' and result.command is None
    assert result.fault.startswith(reason) and c.counters.solver_failures == 1


def test_the_refiner_follows_the_solvers_settings(planar):
    c = cycle(planar, make_solver('daqp', DaqpSettings(primal_tol=1e-8, iter_limit=30), True),
              method='tau-qp-adaptive')
    refiner = c._refiner()
    assert refiner.settings.eps_abs == 1e-8 and refiner.settings.max_iter == 30
    assert refiner.settings.warm_start and c._refiner() is refiner
