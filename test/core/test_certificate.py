# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The certificate catches each kind of wrong answer."""

from grasp_torque_opt.core.certificate import certify
from grasp_torque_opt.methods.dispatch import solve
import numpy as np
import pytest


@pytest.fixture(scope='module')
def good(planar):
    maps = planar.maps()
    sol = solve(planar, maps=maps)
    assert sol.status == 'optimal'
    return planar, maps, sol.tau, sol.wrenches.ravel()


def check(good, tau=None, f=None):
    setup, maps, tau0, f0 = good
    return certify(maps.G, maps.J, setup.external_wrench, setup.friction,
                   -setup.hand.torque_limits, setup.hand.torque_limits,
                   tau0 if tau is None else tau,
                   f0 if f is None else f)


def test_the_optimum_passes(good):
    c = check(good)
    assert c.ok and c.worst < 1e-9


def test_torque_not_produced_by_f_fails(good):
    c = check(good, tau=good[2] + np.array([1e-4, 0, 0, 0]))
    assert not c.ok and c.torque == pytest.approx(1e-4)


def test_unbalanced_wrench_fails(good):
    f = good[3].copy()
    f[2] += 1e-3
    c = check(good, f=f)
    assert not c.ok and c.equilibrium > 1e-4


def test_outside_the_exact_cone_fails(good):
    f = good[3].copy()
    f[0] += 10.0 * f[2]
    assert check(good, f=f).cone > 1.0


def test_over_the_limit_fails(good):
    setup, maps, tau, f = good
    c = certify(maps.G, maps.J, setup.external_wrench, setup.friction,
                -np.abs(tau) * 0.5, np.abs(tau) * 0.5, tau, f)
    assert not c.ok and c.torque_limit > 0


def test_non_finite_fails(good):
    tau = good[2].copy()
    tau[1] = np.nan
    c = check(good, tau=tau)
    assert not c.ok and not c.finite
