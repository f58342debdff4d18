# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Every QP backend: an independent solver's optimum, certified, and no stall on bad data."""

import copy
import dataclasses
import time

from conftest import setup_from_doc
from grasp_torque_opt.backends import BACKENDS, DaqpSolver, make_solver, TauQPSolver
from grasp_torque_opt.backends.daqp import kkt_violation
from grasp_torque_opt.core.exceptions import SolverError
from grasp_torque_opt.core.tau_qp import build_tau_qp
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.reference.force_qp import solve_force_qp
from independent import assert_holds
import numpy as np
import pytest


def force_space_optimum(setup, maps):
    """Tau of the force-space QP with the torque objective (Clarabel), or None if infeasible."""
    raw = solve_force_qp(maps, setup.friction, setup.external_wrench, *setup.tau_bounds,
                         setup.weights, objective='torque')
    return None if raw.status != 'solved' else maps.J.T @ raw.x


@pytest.mark.parametrize('backend', ['daqp', 'quadprog'])
def test_allegro_backends_match_clarabel_on_seeded_loads(backend, allegro):
    rng = np.random.default_rng(7)
    solver = make_solver(backend)
    maps = allegro.maps()
    checked = 0
    for _ in range(20):
        w = allegro.external_wrench * rng.uniform(0.3, 1.5) + np.concatenate(
            (rng.normal(scale=0.3, size=3), rng.normal(scale=0.01, size=3)))
        setup = dataclasses.replace(allegro, external_wrench=w)
        ours = solve(setup, maps=maps, solver=solver)
        ref = force_space_optimum(setup, maps)
        if ref is None:
            assert ours.status == 'infeasible'
            continue
        assert ours.status == 'optimal', ours.message
        assert_holds(setup, maps, ours.tau, ours.wrenches)
        np.testing.assert_allclose(ours.tau, ref, atol=1e-5)
        checked += 1
    assert checked >= 15


@pytest.mark.parametrize('name', ['planar', 'hyperstatic'])
def test_daqp_handles_internal_force_variables(name, request):
    """Z has no cost there (semidefinite Hessian): DAQP's proximal iterations still find tau*."""
    setup = request.getfixturevalue(name)
    maps = setup.maps()
    ours = solve(setup, maps=maps, backend='daqp')
    assert ours.status == 'optimal', ours.message
    np.testing.assert_allclose(ours.tau, force_space_optimum(setup, maps), atol=1e-5)


def test_quadprog_refuses_a_semidefinite_qp(planar):
    sol = solve(planar, backend='quadprog')
    assert sol.status == 'failed' and sol.tau is None
    assert 'positive definite' in sol.message


@pytest.mark.parametrize('backend', BACKENDS)
def test_infeasible_load_is_not_passed_through(backend, allegro):
    heavy = dataclasses.replace(allegro, external_wrench=allegro.external_wrench * 1e4)
    sol = solve(heavy, backend=backend)
    assert sol.status == 'infeasible' and sol.tau is None


@pytest.mark.parametrize('backend', BACKENDS)
@pytest.mark.parametrize('defect', ['nan_in_C', 'inf_in_u', 'inverted_box', 'nan_box'])
def test_bad_qp_data_never_reaches_the_solver(backend, defect, allegro):
    maps = allegro.maps()
    qp = build_tau_qp(maps, allegro.friction, allegro.external_wrench, *allegro.tau_bounds,
                      allegro.weights)
    if defect == 'nan_in_C':
        C = qp.C.copy()
        C[3, 2] = np.nan
        qp = dataclasses.replace(qp, C=C)
    elif defect == 'inf_in_u':
        qp = dataclasses.replace(qp, u=np.where(np.arange(qp.u.size) == 0, np.inf, qp.u))
    elif defect == 'inverted_box':
        qp = dataclasses.replace(qp, l_box=qp.u_box + 0.1)
    else:
        qp = dataclasses.replace(qp, u_box=np.full_like(qp.u_box, np.nan))
    raw = make_solver(backend).solve(qp)
    assert raw.status == 'error' and raw.x is None
    assert 'QP' in raw.message


def test_unknown_backend_is_named():
    with pytest.raises(ValueError, match="proxsuite, daqp, quadprog.*'osqp'"):
        make_solver('osqp')


def moving_sequence(setup, steps):
    """Yield a slowly turning load with drifting fingers: what the node sees cycle to cycle."""
    scale = np.linalg.norm(setup.external_wrench[:3])
    for k in range(steps):
        th = 2 * np.pi * k / steps
        w = setup.external_wrench.copy()
        w[:3] = scale * np.array([np.cos(th), 0.2 * np.sin(3 * th), -abs(np.sin(th)) - 0.3])
        q = setup.q.copy()
        q[setup.hand.idx_q] += 0.03 * np.sin(th)
        yield dataclasses.replace(setup, external_wrench=w, q=q)


WARM_BACKENDS = ['proxsuite', 'daqp']
#: How close two optima of the same QP agree [N m]: ProxSuite stops within about 1e-8 of
#: it at eps_abs 1e-9 (with the duality-gap check), DAQP within 1e-11.
AGREE = {'proxsuite': 1e-7, 'daqp': 1e-8}


@pytest.mark.parametrize('backend', WARM_BACKENDS)
@pytest.mark.parametrize('name', ['planar', 'allegro'])
def test_warm_start_gives_the_cold_optimum(name, backend, request):
    setup = request.getfixturevalue(name)
    cold, warm = make_solver(backend), make_solver(backend, warm_start=True)
    for s in moving_sequence(setup, 40):
        maps = s.maps()
        a, b = solve(s, maps=maps, solver=cold), solve(s, maps=maps, solver=warm)
        assert a.status == b.status
        if a.optimal:
            np.testing.assert_allclose(b.tau, a.tau, atol=AGREE[backend])
    assert warm.warm_solves == 39 and cold.warm_solves == 0


@pytest.mark.parametrize('backend', WARM_BACKENDS)
def test_warm_start_that_fails_falls_back_to_cold_in_the_same_call(allegro, backend):
    """
    From a feasible grasp's solution to an infeasible load and back, each result is the cold one.

    Every warm answer that was not optimal was redone cold (and counted).
    """
    warm = make_solver(backend, warm_start=True)
    heavy = dataclasses.replace(allegro, external_wrench=allegro.external_wrench * 1e3)
    assert solve(allegro, solver=warm).optimal
    assert solve(heavy, solver=warm).status == 'infeasible'
    assert warm.fallbacks == 1  # the warm answer on the heavy load was not optimal
    back = solve(allegro, solver=warm)
    assert back.optimal
    np.testing.assert_allclose(back.tau, solve(allegro, backend='daqp').tau, atol=AGREE[backend])


@pytest.mark.parametrize('backend', WARM_BACKENDS)
def test_warm_start_across_a_change_of_polygon_sides_or_contact_count(planar_doc, backend):
    """
    A QP of another size is a new workspace (cold), then warm again.

    Every answer is the optimum of an independent cold solve.
    """
    warm = make_solver(backend, warm_start=True)
    docs = []
    for sides in (3, 8, 8, 5):
        doc = copy.deepcopy(planar_doc)
        doc['friction']['polygon_sides'] = sides
        docs.append(doc)
    hyper = copy.deepcopy(planar_doc)
    hyper['grasp']['contacts'].insert(1, {'link': 'finger1_distal', 'position': [0, 0.03, 0]})
    docs += [hyper, hyper, planar_doc]
    for doc in docs:
        s = setup_from_doc(doc)
        got, ref = solve(s, solver=warm), solve(s, backend='daqp')
        assert got.status == ref.status == 'optimal'
        np.testing.assert_allclose(got.tau, ref.tau, atol=1e-7)
    assert warm.warm_solves == 2  # the repeated 8-gon and the repeated extra contact


def test_kkt_violation_sees_a_suboptimal_point(allegro):
    """The optimality check itself: the solver's point passes, a feasible detour does not."""
    import daqp

    maps = allegro.maps()
    qp = build_tau_qp(maps, allegro.friction, allegro.external_wrench, *allegro.tau_bounds,
                      allegro.weights)
    n, n_eq = qp.H.shape[0], qp.A.shape[0]
    A = np.vstack((qp.A, qp.C))
    lower = np.concatenate((qp.l_box, qp.b, np.full(qp.C.shape[0], -1e30)))
    upper = np.concatenate((qp.u_box, qp.b, qp.u))
    sense = np.zeros(n + A.shape[0], dtype=np.int32)
    sense[n:n + n_eq] = 5
    x, _, flag, info = daqp.solve(qp.H.copy(), qp.g, A, upper, lower, sense, primal_tol=1e-9)
    assert flag == 1
    lam = info['lam']
    assert kkt_violation(qp.H, qp.g, A, lower, upper, x, lam) < 1e-9
    # Written out independently: stationarity with the full constraint matrix.
    M = np.vstack((np.eye(n), A))
    assert np.abs(qp.H @ x + qp.g + M.T @ lam).max() < 1e-9
    assert kkt_violation(qp.H, qp.g, A, lower, upper, x * 1.01, lam) > 1e-4  # moved
    assert kkt_violation(qp.H, qp.g, A, lower, upper, x, -lam) > 1e-4  # wrong signs
    assert kkt_violation(qp.H, qp.g, A, lower, upper, x, np.zeros_like(lam)) > 1e-4


class WrongAnswer:
    """A first backend that claims SOLVED with a finite, wrong x (fault injection)."""

    name = 'wrong'

    def __init__(self, raises: bool = False):
        self.inner, self.raises = make_solver('proxsuite'), raises
        self.settings = self.inner.settings

    def solve(self, qp):
        if self.raises:
            raise SolverError('injected')
        good = self.inner.solve(qp)
        return dataclasses.replace(good, x=good.x + 0.05)


@pytest.mark.parametrize('raises', [False, True])
def test_fallback_backend_answers_when_the_first_fails(allegro, raises):
    maps = allegro.maps()
    alone = solve(allegro, maps=maps, solver=WrongAnswer()) if not raises else None
    if alone is not None:
        assert alone.status == 'failed' and alone.tau is None
    sol = solve(allegro, maps=maps, solver=WrongAnswer(raises), fallback=make_solver('daqp'))
    assert sol.status == 'optimal' and sol.backend == 'daqp'
    assert 'fallback after' in sol.message
    np.testing.assert_allclose(sol.tau, force_space_optimum(allegro, maps), atol=1e-5)
    assert_holds(allegro, maps, sol.tau, sol.wrenches)


def test_fallback_is_not_asked_when_the_first_backend_certifies(allegro):
    class Counting:
        name, calls = 'counting', 0

        def solve(self, qp):
            Counting.calls += 1
            return make_solver('daqp').solve(qp)

    sol = solve(allegro, fallback=Counting())
    assert sol.optimal and sol.backend == 'proxsuite' and Counting.calls == 0


@pytest.mark.parametrize('backend', WARM_BACKENDS)
def test_warm_answer_off_the_certificate_is_redone_cold(allegro, backend):
    """
    A warm answer that the certificate refuses is solved again cold in the same call, and counted.

    The solver accepts the answer; the fault is injected (the warm x moved by 5%).
    """
    base = {'daqp': DaqpSolver, 'proxsuite': TauQPSolver}[backend]

    class WrongWhenWarm(base):

        def solve(self, qp, cold=False):
            raw = super().solve(qp, cold)
            return dataclasses.replace(raw, x=raw.x * 1.05) if self.last_warm else raw

    warm = WrongWhenWarm(warm_start=True)
    first = moving_sequence(allegro, 40)
    assert solve(next(first), solver=warm).optimal  # cold: a new workspace
    moved = next(first)
    sol = solve(moved, solver=warm)
    assert warm.warm_solves == 1 and warm.fallbacks == 1
    assert sol.optimal and sol.backend == backend
    np.testing.assert_allclose(sol.tau, solve(moved, backend='daqp').tau, atol=AGREE[backend])


def drifting_rotating(setup, steps):
    """
    Yield the load's force rotating once around base y, every joint drifting by up to 0.05 rad.

    This is the sequence on which ProxSuite's warm start stopped off the optimum, saying
    solved.
    """
    scale = np.linalg.norm(setup.external_wrench[:3])
    phase = np.random.default_rng(0).uniform(0, 2 * np.pi, setup.hand.m)
    for k in range(steps):
        th = 2 * np.pi * k / steps
        q = setup.q.copy()
        q[setup.hand.idx_q] += 0.05 * np.sin(th + phase)
        w = np.array([scale * np.cos(th), 0.0, scale * np.sin(th), 0.0, 0.0, 0.0])
        yield dataclasses.replace(setup, q=q, external_wrench=w)


def test_proxsuite_warm_answers_are_the_optimum_on_a_drifting_grasp(allegro):
    """
    Every answer of the warm solver equals an independent solver's optimum (DAQP, cold).

    A warm answer that stopped on a stale active set is caught by the KKT check and redone.
    """
    warm = make_solver('proxsuite', warm_start=True)
    for s in drifting_rotating(allegro, 500):
        qp = build_tau_qp(s.maps(), s.friction, s.external_wrench, *s.tau_bounds, s.weights)
        got, ref = warm.solve(qp), make_solver('daqp').solve(qp)
        assert got.status == ref.status == 'solved'
        np.testing.assert_allclose(qp.split(got.x)[0], qp.split(ref.x)[0], atol=1e-6)
    assert warm.warm_solves == 499 and 0 < warm.fallbacks < 50


def test_proxsuite_kkt_check_sees_a_suboptimal_point(allegro):
    """
    The optimality check itself: ProxSuite's cold answer passes.

    The same point with a multiplier of the wrong sign, or moved along the feasible set, does
    not.
    """
    from grasp_torque_opt.backends.proxsuite import KKT_TOLERANCE, kkt_violation

    maps = allegro.maps()
    qp = build_tau_qp(maps, allegro.friction, allegro.external_wrench, *allegro.tau_bounds,
                      allegro.weights)
    solver = TauQPSolver()
    assert solver.solve(qp).status == 'solved'
    r = solver._qp.results
    x, y, z = np.array(r.x), np.array(r.y), np.array(r.z)
    assert kkt_violation(qp, x, y, z) <= KKT_TOLERANCE
    wrong = z.copy()
    wrong[int(np.argmax(z[:qp.C.shape[0]]))] *= -1.0
    assert kkt_violation(qp, x, y, wrong) > KKT_TOLERANCE
    assert kkt_violation(qp, 0.9 * x, y, z) > KKT_TOLERANCE


# -- time budgets ---------------------------------------------------------------------------


def hard_qp(allegro, ratio=1e24):
    """
    Build the Allegro's QP with weights 1e-12 and 1e12 alternating: ProxSuite runs to its caps.

    This is the issue's freeze: over 11 minutes with caps 100000 x 100000.
    """
    w = np.array([1.0 / np.sqrt(ratio), np.sqrt(ratio)] * (allegro.hand.m // 2))
    return build_tau_qp(allegro.maps(), allegro.friction, allegro.external_wrench,
                        *allegro.tau_bounds, w)


def test_a_deadline_stops_proxsuite_whatever_its_caps(allegro):
    from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings

    solver = TauQPSolver(ProxSuiteSettings(max_iter=100000, max_iter_in=200))
    t0 = time.perf_counter()
    raw = solver.solve(hard_qp(allegro), deadline=t0 + 0.05)
    elapsed = time.perf_counter() - t0
    assert raw.status == 'error' and raw.message.startswith('time budget spent after ')
    # At most one outer iteration (200 inner ones, well under 0.5 s here) past the deadline.
    assert elapsed < 0.05 + 0.5 and solver.timeouts == 1


def test_a_deadline_leaves_an_ordinary_solve_alone(allegro):
    """
    A solve that fits in its budget is one ProxSuite call: bit for bit the same answer.

    Cut into the shortest slices (continued from each slice's result), it still converges to
    the same optimum.
    """
    qp = build_tau_qp(allegro.maps(), allegro.friction, allegro.external_wrench,
                      *allegro.tau_bounds, allegro.weights)
    plain = TauQPSolver().solve(qp)
    timed = TauQPSolver().solve(qp, deadline=time.perf_counter() + 10.0)
    assert plain.status == timed.status == 'solved'
    np.testing.assert_array_equal(plain.x, timed.x)
    sliced = TauQPSolver(max_slice_s=1e-9)
    sliced._inner_s = 1.0  # every slice as short as allowed (MIN_SLICE_OUTER)
    got = sliced.solve(qp, deadline=time.perf_counter() + 10.0)
    assert got.status == 'solved'
    np.testing.assert_allclose(got.x[:allegro.hand.m], plain.x[:allegro.hand.m], atol=1e-7)


@pytest.mark.parametrize('backend', ['daqp', 'quadprog'])
def test_no_active_set_solve_starts_past_its_deadline(allegro, backend):
    raw = make_solver(backend).solve(hard_qp(allegro, 1.0), deadline=time.perf_counter() - 1.0)
    assert raw.status == 'error' and 'time budget spent' in raw.message and raw.x is None


def test_solve_splits_its_deadline_and_skips_the_lp_when_spent(allegro):
    """
    dispatch.solve under a deadline: the fallback still answers after the first backend stopped.

    The first backend stopped by its share; past the deadline nothing more runs (no LP).
    """
    from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings

    hard = dataclasses.replace(allegro, weights=np.array([1e-12, 1e12] * 8))
    slow = TauQPSolver(ProxSuiteSettings(max_iter=100000, max_iter_in=200))
    t0 = time.perf_counter()
    sol = solve(hard, solver=slow, fallback=make_solver('daqp'), deadline=t0 + 0.05)
    assert time.perf_counter() - t0 < 0.05 + 0.5
    assert slow.timeouts == 1 and 'fallback' in sol.timings  # DAQP had its turn
    spent = solve(allegro, solver=TauQPSolver(), deadline=time.perf_counter() - 1.0)
    assert spent.status == 'failed' and 'LP skipped: time budget spent' in spent.message


def test_a_deadline_caps_daqps_iterations(allegro):
    """
    Under a deadline DAQP's iteration cap is the iterations that fit.

    DAQP cycled for 1677 iterations (146 ms here) on a 32-contact grasp with weights at the
    ratio bound.
    """
    from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings
    from grasp_torque_opt.core.scenario_fields import ContactSpec

    rng = np.random.default_rng(0)
    contacts = [ContactSpec(link=c.link, position=c.position + rng.normal(0, 2e-3, 3))
                for c in allegro.contacts * 8]
    big = dataclasses.replace(allegro, contacts=contacts)
    w = np.array([1e-3, 1e3] * 8)
    qp = build_tau_qp(big.maps(), big.friction, big.external_wrench, *big.tau_bounds, w)
    solver = make_solver('daqp', ProxSuiteSettings(max_iter=10000))
    free = solver.solve(qp)
    t0 = time.perf_counter()
    capped = solver.solve(qp, deadline=t0 + 0.01)
    elapsed = time.perf_counter() - t0
    assert capped.iterations < free.iterations and elapsed < 0.01 + 0.5
