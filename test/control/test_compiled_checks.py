# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The cycle's checks in one compiled call each, against their numpy forms.

The gate of a command (:func:`~grasp_torque_opt.control.cycle.checked_command`), the rate
rule's shortcut (:func:`~grasp_torque_opt.control.rates.within_step`) and a known joint
state's positions (``fast_cycle.take_positions``) run in C++ where the module is built:
the same answers as numpy's on random draws with values over the limits, at them, NaN
and Inf.
"""

import os

from cycle_inputs import fresh, joint_state
from grasp_torque_opt.control import cycle, rates
from grasp_torque_opt.control.cycle import (
    checked_command,
    checked_command_numpy,
    NOT_FINITE,
    SIZES_DIFFER,
)
from grasp_torque_opt.control.inputs import joint_states
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.rates import within_step, within_step_numpy
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.native import loader
import numpy as np
import pytest

pytestmark = pytest.mark.skipif(
    bool(os.environ.get('GRASP_TORQUE_OPT_NO_COMPILED')) or loader.fast_cycle is None,
    reason='GRASP_TORQUE_OPT_NO_COMPILED: built without the compiled cycle on purpose')


def draws(rng, n, count):
    """Yield arrays of n values: within, near and over 1, with NaN and Inf now and then."""
    for _ in range(count):
        x = rng.uniform(-1.3, 1.3, n) * rng.choice([0.5, 1.0, 1.0, 2.0])
        if rng.random() < 0.1:
            x[rng.integers(n)] = rng.choice([np.nan, np.inf, -np.inf])
        if rng.random() < 0.1:
            x[rng.integers(n)] = rng.choice([1.0, -1.0]) * 0.98  # at the fraction exactly
        yield x


def test_the_gate_gives_numpys_command_verdict_and_limit_flag():
    rng = np.random.default_rng(11)
    limits = rng.uniform(0.5, 2.0, 16)
    seen = set()
    for x in draws(rng, 16, 5000):
        tau = x * limits
        g = None if rng.random() < 0.3 else rng.uniform(-0.1, 0.1, 16)
        got, want = checked_command(tau, g, limits, 0.98), checked_command_numpy(
            tau, g, limits, 0.98)
        np.testing.assert_array_equal(got[0], want[0])
        assert got[1:] == want[1:]
        seen.add(min(got[1], 0))
        seen.add(('at', got[2]))
    assert seen == {-1, NOT_FINITE, 0, ('at', True), ('at', False)}  # every verdict drawn
    # the compiled call is the one asked, and a size that differs is numpy's to name
    cmd, worst, _ = loader.fast_cycle.gate_command(limits * 1.5, np.zeros(0), limits, 0.98)
    assert worst == int(np.argmax(limits * 0.5)) and cmd.shape == (16,)
    assert checked_command(np.zeros(15), None, limits, 0.98)[1] == SIZES_DIFFER


def test_within_step_is_numpys_on_any_values_and_shapes():
    rng = np.random.default_rng(12)
    seen = {True: 0, False: 0}
    for x in draws(rng, 7, 5000):
        a = rng.uniform(-1.0, 1.0, 7)
        b, step = a + 0.1 * x, 0.1 * rng.uniform(0.5, 1.5)
        within = within_step(a, b, step)
        assert within == within_step_numpy(a, b, step)
        assert within == loader.fast_cycle.within_step(a, b, step)
        seen[within] += 1
    assert min(seen.values()) > 500
    assert within_step(np.zeros(0), np.zeros(0), 0.0)
    assert not within_step(np.zeros(4), np.zeros((2, 2)), 1.0)
    assert not loader.fast_cycle.within_step(np.zeros(4), np.zeros((2, 2)), 1.0)


def test_take_positions_puts_only_positions_all_within_their_bounds():
    rng = np.random.default_rng(13)
    low, high = -np.ones(5), np.ones(5)
    pick, put = np.array([4, 0, 2, 5, 1]), np.array([7, 1, 3, 0, 6])
    taken = 0
    for x in draws(rng, 6, 3000):
        positions = x.tolist()  # as a JointStateReading gives them
        q = rng.uniform(-1.0, 1.0, 8)
        before = q.copy()
        ok = loader.fast_cycle.take_positions(positions, pick, low, high, q, put)
        values = x[pick]
        assert ok == bool(((values >= low) & (values <= high)).all())
        want = before.copy()
        if ok:
            want[put] = values
            taken += 1
        np.testing.assert_array_equal(q, want)  # untouched when refused
    assert 300 < taken < 2700
    with pytest.raises(ValueError, match='out of range'):
        loader.fast_cycle.take_positions([0.0] * 3, pick, low, high, np.zeros(8), put)
    with pytest.raises(TypeError):  # a copy would be written, not q: refused
        loader.fast_cycle.take_positions([0.0] * 6, pick, low, high, np.zeros(8, int), put)


def run_cycles(setup, states):
    """Run a controller of its own on joint states a millisecond apart; what each gave."""
    ctrl = fresh(setup, gravity_compensation=True, max_torque_rate=2.0)
    names = joint_state(setup)[0]
    out = []
    for k, positions in enumerate(states):
        now = 1.0 + 1e-3 * k
        try:
            ctrl.take('joint_states', JointStateReading(names, positions), now)
        except InputError as e:
            out.append(('rejected', str(e), None))
            continue
        r = ctrl.cycle(now)
        out.append((r.kind, r.fault, None if r.command is None else r.command.copy()))
    return out, ctrl.counters


def test_the_cycle_is_the_same_with_the_checks_numpy_forms(allegro, monkeypatch):
    # Where the module is not built, the numpy forms run: the same cycle, state for state,
    # with positions rejected (NaN, beyond a limit) and steps cut by the rate rule.
    rng = np.random.default_rng(14)
    q0 = np.array(joint_state(allegro)[1])
    states = []
    for k in range(120):
        q = q0 + 0.03 * np.sin(0.05 * k) + rng.normal(0.0, 2e-3, q0.size)
        if k % 17 == 5:
            q[k % q0.size] = np.nan
        if k % 23 == 7:
            q[k % q0.size] = 40.0  # beyond the URDF's limits
        states.append(q.tolist())
    compiled, counted = run_cycles(allegro, states)
    for module in (cycle, rates, joint_states):
        monkeypatch.setattr(module, 'fast_cycle', None)
    numpy_forms, counted_numpy = run_cycles(allegro, states)
    assert len(compiled) == len(numpy_forms) == len(states)
    for a, b in zip(compiled, numpy_forms):
        assert a[:2] == b[:2]
        assert (a[2] is None) == (b[2] is None)
        if a[2] is not None:  # to rounding: two runs of the same code differed by 3e-16 N m
            np.testing.assert_allclose(a[2], b[2], rtol=0.0, atol=1e-12)
    kinds = [a[0] for a in compiled]
    assert kinds.count('rejected') >= 10 and kinds.count('solution') >= 90
    assert counted.slew_limited == counted_numpy.slew_limited > 10  # both sides of the rule
    assert counted.slew_limited < kinds.count('solution')
    assert counted.rejected == counted_numpy.rejected
