# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The tau-space QP: its pieces, and its optimum against independent formulations and solvers."""

import dataclasses

from grasp_torque_opt.backends import make_solver
from grasp_torque_opt.backends.proxsuite import TauQPSolver
from grasp_torque_opt.core.tau_qp import build_tau_qp, decompose
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.reference.exact_socp import solve_exact_socp
from grasp_torque_opt.reference.force_qp import solve_force_qp
from independent import assert_holds, lp_feasible
import numpy as np
import pytest

CASES = ['planar', 'hyperstatic', 'allegro']


def built(setup):
    maps = setup.maps()
    return maps, build_tau_qp(maps, setup.friction, setup.external_wrench,
                              *setup.tau_bounds, setup.weights)


@pytest.mark.parametrize('name', CASES)
def test_parametrization_balances_the_load(name, request):
    setup = request.getfixturevalue(name)
    maps, qp = built(setup)
    A = np.vstack((maps.G, maps.J.T))
    np.testing.assert_allclose(A @ qp.N, 0, atol=1e-12)
    # Any tau that meets the compatibility rows gives f with G f = w, J^T f = tau.
    rng = np.random.default_rng(2)
    tau = rng.normal(size=qp.m)
    if qp.A.shape[0]:
        Aeq = qp.A[:, :qp.m]
        tau -= np.linalg.lstsq(Aeq, Aeq @ tau - qp.b, rcond=None)[0]
    x = np.concatenate((tau, rng.normal(size=qp.N.shape[1])))
    np.testing.assert_allclose(A @ qp.wrenches(x), np.concatenate((qp.w, tau)), atol=1e-9)


def test_planar_grasp_is_rank_deficient_and_solves(planar):
    maps, qp = built(planar)
    assert np.linalg.matrix_rank(np.vstack((maps.G, maps.J.T))) < 4 * maps.p
    assert qp.N.shape[1] >= 1, 'internal forces the joints cannot feel need z'
    assert qp.A.shape[0] >= 1, 'the compatibility equalities are needed'
    sol = solve(planar)
    assert sol.status == 'optimal'
    assert_holds(planar, maps, sol.tau, sol.wrenches)


def test_hyperstatic_grasp_solves(hyperstatic):
    maps = hyperstatic.maps()
    assert maps.p == 3 and [c.link for c in maps.contacts][:2] == ['finger1_tip',
                                                                   'finger1_distal']
    sol = solve(hyperstatic)
    assert sol.status == 'optimal'
    assert_holds(hyperstatic, maps, sol.tau, sol.wrenches)


def torque_objective(setup, tau):
    return float(tau @ (setup.weights * tau))


@pytest.mark.parametrize('name', CASES)
def test_optimum_equals_force_space_qp_with_torque_objective(name, request):
    setup = request.getfixturevalue(name)
    maps = setup.maps()
    ours = solve(setup, maps=maps)
    raw = solve_force_qp(maps, setup.friction, setup.external_wrench,
                         *setup.tau_bounds, setup.weights, objective='torque')
    assert raw.status == 'solved'
    tau_f = maps.J.T @ raw.x
    assert ours.status == 'optimal'
    assert torque_objective(setup, ours.tau) == pytest.approx(
        torque_objective(setup, tau_f), rel=1e-6, abs=1e-9)
    np.testing.assert_allclose(ours.tau, tau_f, atol=1e-5)


@pytest.mark.parametrize('name', CASES)
def test_never_below_the_exact_cone_optimum(name, request):
    setup = request.getfixturevalue(name)
    maps = setup.maps()
    ours = solve(setup, maps=maps)
    raw = solve_exact_socp(maps, setup.friction, setup.external_wrench,
                           *setup.tau_bounds, setup.weights)
    exact = maps.J.T @ raw.x[:4 * maps.p]
    assert torque_objective(setup, ours.tau) >= torque_objective(setup, exact) - 1e-8


def test_random_allegro_grasps_agree_with_independent_solvers(allegro):
    """Seeded loads on the Allegro grasp: same optimum as the force-space QP, above the SOCP."""
    rng = np.random.default_rng(42)
    solver = TauQPSolver()
    maps = allegro.maps()
    base = allegro.external_wrench
    checked = 0
    for _ in range(25):
        w = base * rng.uniform(0.3, 1.5) + np.concatenate(
            (rng.normal(scale=0.3, size=3), rng.normal(scale=0.01, size=3)))
        setup = dataclasses.replace(allegro, external_wrench=w)
        ours = solve(setup, maps=maps, solver=solver)
        raw = solve_force_qp(maps, setup.friction, w, *setup.tau_bounds, setup.weights,
                             objective='torque')
        if ours.status != 'optimal':
            assert ours.status == 'infeasible' and raw.status == 'infeasible'
            continue
        checked += 1
        assert_holds(setup, maps, ours.tau, ours.wrenches)
        tau_f = maps.J.T @ raw.x
        assert torque_objective(setup, ours.tau) == pytest.approx(
            torque_objective(setup, tau_f), rel=1e-6, abs=1e-9)
        exact = solve_exact_socp(maps, setup.friction, w, *setup.tau_bounds, setup.weights)
        tau_x = maps.J.T @ exact.x[:4 * maps.p]
        assert torque_objective(setup, ours.tau) >= torque_objective(setup, tau_x) - 1e-8
    assert checked >= 15


def test_weights_shift_effort(planar):
    """A heavier weight on a joint lowers its share of the effort, still certified."""
    heavy = dataclasses.replace(planar, weights=np.array([10.0, 1.0, 1.0, 1.0]))
    a, b = solve(planar), solve(heavy)
    assert b.status == 'optimal'
    assert abs(b.tau[0]) <= abs(a.tau[0]) + 1e-9
    assert_holds(heavy, heavy.maps(), b.tau, b.wrenches)


@pytest.mark.parametrize('name', CASES)
def test_decomposition_against_numpy_pinv(name, request):
    """QR path (full column rank) or SVD path: pinv, null space and left null space are right."""
    maps = request.getfixturevalue(name).maps()
    A = np.vstack((maps.G, maps.J.T))
    pinv, N, U_perp = decompose(A)
    rank = np.linalg.matrix_rank(A)
    np.testing.assert_allclose(pinv, np.linalg.pinv(A, rcond=1e-10), atol=1e-9)
    assert N.shape == (A.shape[1], A.shape[1] - rank)
    assert U_perp.shape == (A.shape[0], A.shape[0] - rank)
    np.testing.assert_allclose(A @ N, 0, atol=1e-12)
    np.testing.assert_allclose(U_perp.T @ A, 0, atol=1e-12)
    np.testing.assert_allclose(U_perp.T @ U_perp, np.eye(U_perp.shape[1]), atol=1e-12)


def test_feasible_load_is_not_declared_infeasible(allegro):
    """A load ProxSuite called PRIMAL_INFEASIBLE with eps_primal_inf 1e-8 (the LP holds it)."""
    th = 2 * np.pi * 3 / 500
    w = np.array([1.4715 * np.cos(th), 0.0, 1.4715 * np.sin(th), 0.0, 0.0, 0.0])
    setup = dataclasses.replace(allegro, external_wrench=w)
    maps = setup.maps()
    assert lp_feasible(setup, maps)
    sol = solve(setup, maps=maps)
    assert sol.status == 'optimal', sol.message
    assert_holds(setup, maps, sol.tau, sol.wrenches)


def test_a_hessian_that_is_not_diagonal_is_solved_as_dense(allegro):
    """
    A coupled H must still give its own optimum, though the default Hessian type is Diagonal.

    build_tau_qp's H is diagonal; the optimum is the one DAQP finds for the coupled H, not
    the diagonal one.
    """
    maps = allegro.maps()
    qp = build_tau_qp(maps, allegro.friction, allegro.external_wrench, *allegro.tau_bounds,
                      allegro.weights)
    v = np.linspace(1.0, 2.0, qp.m)
    coupled = dataclasses.replace(qp, H=qp.H + 4.0 * np.outer(v, v))
    x = TauQPSolver().solve(coupled).x
    ref = make_solver('daqp').solve(coupled).x
    diagonal_only = TauQPSolver().solve(qp).x
    np.testing.assert_allclose(x, ref, atol=1e-6)
    assert np.abs(x - diagonal_only).max() > 1e-3
