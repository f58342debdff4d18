# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
DaqpWorkspace, the adaptive method's rounds: the same optimum as an independent solver.

Its multipliers are a KKT point, warm and cold alike, and bad data is refused.
"""

from grasp_torque_opt.backends.daqp import DaqpWorkspace, kkt_violation
from grasp_torque_opt.core.tau_qp import build_tau_qp
from grasp_torque_opt.reference.force_qp import solve_force_qp
import numpy as np
import pytest


def built(setup):
    maps = setup.maps()
    return maps, build_tau_qp(maps, setup.friction, setup.external_wrench, *setup.tau_bounds,
                              setup.weights)


def loaded(qp):
    ws = DaqpWorkspace()
    ws.load(qp.H, qp.g, qp.A, qp.b, qp.C, qp.u, qp.l_box, qp.u_box,
            semidefinite=qp.H.shape[0] > qp.m)
    return ws


@pytest.mark.parametrize('name', ['planar', 'allegro'])
def test_optimum_and_multipliers(name, request):
    setup = request.getfixturevalue(name)
    maps, qp = built(setup)
    ws = loaded(qp)
    raw = ws.solve()
    assert raw.status == 'solved'
    tau = raw.x[:qp.m]
    ref = solve_force_qp(maps, setup.friction, setup.external_wrench, *setup.tau_bounds,
                         setup.weights, objective='torque')  # Clarabel, force space
    tau_ref = maps.J.T @ ref.x
    assert tau @ (setup.weights * tau) == pytest.approx(tau_ref @ (setup.weights * tau_ref),
                                                        rel=1e-6)
    A = np.vstack((qp.A, qp.C))
    big = 1e30  # DAQP's infinity, as kkt_violation expects
    lower = np.concatenate((np.maximum(qp.l_box, -big), qp.b, np.full(qp.C.shape[0], -big)))
    upper = np.concatenate((np.minimum(qp.u_box, big), qp.b, qp.u))
    assert kkt_violation(qp.H, qp.g, A, lower, upper, raw.x, ws.multipliers) < 1e-6


def test_warm_and_cold_agree_and_data_can_change(allegro):
    _, qp = built(allegro)
    ws = loaded(qp)
    first = ws.solve().x
    np.testing.assert_allclose(ws.solve().x, first, atol=1e-9)  # warm, same data
    looser = qp.u + 0.05
    warm = ws.solve(u=looser)
    cold = ws.solve(u=looser, cold=True)
    assert warm.status == cold.status == 'solved'
    np.testing.assert_allclose(warm.x, cold.x, atol=1e-7)
    assert np.abs(warm.x - first).max() > 1e-6  # the new rows were used


def test_non_finite_data_is_refused_and_a_failure_is_an_error(allegro):
    _, qp = built(allegro)
    ws = loaded(qp)
    u = qp.u.copy()
    u[3] = np.nan
    raw = ws.solve(u=u)
    assert raw.status == 'error' and 'not finite' in raw.message and ws.multipliers is None
    capped = DaqpWorkspace(max_iter=1)
    capped.load(qp.H, qp.g, qp.A, qp.b, qp.C, qp.u, qp.l_box, qp.u_box, semidefinite=False)
    raw = capped.solve()
    assert raw.status == 'error' and capped.multipliers is None
