# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
tau-qp-adaptive: certified answers within bounds that bracket the independent SOCP.

The bounds bracket the independent SOCP, the answer is certified and within its gap of
it, the planar excess is closed, a failed round falls back to the paper's polygon.
"""

import dataclasses
import math

from grasp_torque_opt.backends.daqp import DaqpWorkspace
from grasp_torque_opt.core.exceptions import SolverError
from grasp_torque_opt.methods.adaptive import AdaptiveSettings, Refiner
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.reference.exact_socp import solve_exact_socp
from independent import assert_holds
import numpy as np
import pytest

CASES = ['planar', 'hyperstatic', 'allegro']
#: Clarabel's optimum is as exact as its tolerances (1e-10): the bracket allows this much.
SLACK = 1e-8


def exact_norm(setup, maps):
    """sqrt(tau^T W tau) at the exact-cone optimum, from reference.exact_socp (Clarabel)."""
    raw = solve_exact_socp(maps, setup.friction, setup.external_wrench, *setup.tau_bounds,
                           setup.weights)
    assert raw.status == 'solved', raw.message
    tau = maps.J.T @ raw.x[:4 * maps.p]
    return math.sqrt(float(tau @ (setup.weights * tau)))


def weighted_norm(setup, tau):
    return math.sqrt(float(tau @ (setup.weights * tau)))


def check_against_socp(setup, maps, sol):
    """Certified, holds the load (independent check), bounds bracket E, within its gap of E."""
    assert sol.status == 'optimal', sol.message
    assert sol.certificate.ok
    assert_holds(setup, maps, sol.tau, sol.wrenches)
    E, b = exact_norm(setup, maps), sol.bounds
    assert b.lower is not None and b.lower <= E * (1 + SLACK), (b, E)
    assert b.upper >= E * (1 - SLACK), (b, E)
    assert b.upper == pytest.approx(weighted_norm(setup, sol.tau), rel=1e-12)
    assert weighted_norm(setup, sol.tau) <= E * (1 + b.gap + SLACK)
    return E


@pytest.mark.parametrize('name', CASES)
def test_bounds_bracket_the_socp_and_the_gap_is_met(name, request):
    setup = request.getfixturevalue(name)
    maps = setup.maps()
    sol = solve(setup, 'tau-qp-adaptive', maps=maps)
    check_against_socp(setup, maps, sol)
    assert sol.bounds.converged and sol.bounds.gap <= 1e-3
    assert sol.bounds.source in ('refined', 'circumscribed')


def test_random_allegro_loads_one_refiner(allegro):
    """
    Seeded loads, one Refiner reused (its workspace carries over).

    Every answer is certified, bracketed and within its gap; each equals a fresh Refiner's.
    """
    rng = np.random.default_rng(11)
    maps = allegro.maps()
    refiner = Refiner()
    checked = 0
    for _ in range(20):
        w = allegro.external_wrench * rng.uniform(0.3, 1.5) + np.concatenate(
            (rng.normal(scale=0.3, size=3), rng.normal(scale=0.01, size=3)))
        setup = dataclasses.replace(allegro, external_wrench=w)
        sol = solve(setup, 'tau-qp-adaptive', maps=maps, refiner=refiner)
        if sol.status == 'infeasible':
            continue
        check_against_socp(setup, maps, sol)
        fresh = solve(setup, 'tau-qp-adaptive', maps=maps)
        np.testing.assert_allclose(sol.tau, fresh.tau, atol=1e-9)
        checked += 1
    assert checked >= 15


def test_lower_bound_never_above_the_socp_for_any_polygon(planar, allegro):
    """Round 0 alone (max_rounds 0): the circumscribed N-gon's bound, for several N."""
    for setup in (planar, allegro):
        maps = setup.maps()
        E = exact_norm(setup, maps)
        for sides in (3, 4, 8, 16):
            refiner = Refiner(AdaptiveSettings(max_rounds=0, first_sides=sides))
            sol = solve(setup, 'tau-qp-adaptive', maps=maps, refiner=refiner)
            assert sol.optimal
            assert sol.bounds.lower <= E * (1 + SLACK)
            assert sol.bounds.upper >= E * (1 - SLACK)


def test_planar_case_closes_the_excess_of_the_papers_triangle(planar):
    """
    N = 3 (the paper's): the adaptive torque is within 0.1% of the exact optimum.

    The polygon's torque is about 80% above the exact optimum; the adaptive one's certified
    gap says so too.
    """
    maps = planar.maps()
    E = exact_norm(planar, maps)
    polygon = solve(planar, maps=maps)
    sol = solve(planar, 'tau-qp-adaptive', maps=maps)
    assert polygon.torque_norm / E - 1 > 0.5
    assert weighted_norm(planar, sol.tau) / E - 1 < 1e-3
    assert sol.bounds.gap < 1e-3
    check_against_socp(planar, maps, sol)


def test_round_zero_bound_is_the_circumscribed_polygon_of_the_scenario(planar):
    """
    max_rounds 0 with the scenario's N: the answer is the paper's N-gon's.

    Or it is the outer polygon's own, if certified; the lower bound comes from the same N
    scaled out.
    """
    maps = planar.maps()
    sol = solve(planar, 'tau-qp-adaptive', maps=maps,
                refiner=Refiner(AdaptiveSettings(max_rounds=0)))
    polygon = solve(planar, maps=maps)
    assert sol.bounds.source == 'polygon' and sol.bounds.rounds == 0
    np.testing.assert_allclose(sol.tau, polygon.tau, atol=1e-9)
    E = exact_norm(planar, maps)
    assert sol.bounds.lower <= E <= sol.bounds.upper
    assert sol.bounds.gap > 0.5  # the triangle's gap is wide: that is what the rounds close


def test_a_failing_solver_falls_back_to_the_papers_polygon(allegro):
    """
    Real DAQP with a cap of one iteration fails every round.

    The answer is then the paper's N-gon's (certified), never nothing.
    """
    maps = allegro.maps()
    refiner = Refiner(AdaptiveSettings(max_iter=1))
    sol = solve(allegro, 'tau-qp-adaptive', maps=maps, refiner=refiner)
    polygon = solve(allegro, maps=maps)
    assert sol.status == 'optimal' and sol.bounds.source == 'polygon'
    assert 'round 0' in sol.message
    np.testing.assert_allclose(sol.tau, polygon.tau, atol=1e-9)
    assert sol.bounds.lower is None and sol.bounds.upper == pytest.approx(
        weighted_norm(allegro, polygon.tau))
    assert_holds(allegro, maps, sol.tau, sol.wrenches)


class RaisesOnSecondSolve(DaqpWorkspace):
    """
    DAQP itself, raising on its second QP of a grasp.

    The real solver cannot be made to fail on demand in one round only (its settings apply
    to every round).
    """

    def load(self, *args, **kwargs):
        self.calls = 0
        super().load(*args, **kwargs)

    def solve(self, *args, **kwargs):
        self.calls += 1
        if self.calls == 2:
            raise SolverError('DAQP failed: injected in round 1')
        return super().solve(*args, **kwargs)


def test_a_round_that_raises_keeps_round_zeros_bound_and_falls_back(allegro):
    maps = allegro.maps()
    sol = solve(allegro, 'tau-qp-adaptive', maps=maps,
                refiner=Refiner(workspace=RaisesOnSecondSolve()))
    polygon = solve(allegro, maps=maps)
    assert sol.status == 'optimal' and sol.bounds.source == 'polygon'
    assert 'injected in round 1' in sol.message
    np.testing.assert_allclose(sol.tau, polygon.tau, atol=1e-9)
    E = exact_norm(allegro, maps)
    assert sol.bounds.lower is not None and sol.bounds.lower <= E * (1 + SLACK)
    assert sol.bounds.upper >= E


def test_heavy_load_is_infeasible_even_for_the_outer_polygon(planar):
    heavy = dataclasses.replace(planar, external_wrench=planar.external_wrench * 200.0)
    sol = solve(heavy, 'tau-qp-adaptive')
    assert sol.status == 'infeasible', sol.message
    assert sol.tau is None and 'circumscribed' in sol.message
    assert solve(heavy, 'socp').status == 'infeasible'


def test_holds_a_load_the_papers_triangle_cannot(allegro):
    """
    With N = 3 some loads are lost to the polygon but not to the exact cone.

    The adaptive method, whose outer polygon contains the exact cone, still finds the exact
    optimum.
    """
    rng = np.random.default_rng(5)
    tri = dataclasses.replace(allegro, friction=dataclasses.replace(allegro.friction, sides=3))
    maps = tri.maps()
    weight = float(np.linalg.norm(tri.external_wrench[:3]))
    for _ in range(40):  # loads of random direction, up to three times the ball's weight
        d = rng.normal(size=3)
        w = np.concatenate((d / np.linalg.norm(d) * weight * rng.uniform(0.3, 3.0),
                            rng.normal(scale=0.004, size=3)))
        setup = dataclasses.replace(tri, external_wrench=w)
        if solve(setup, maps=maps).status == 'infeasible' and \
                solve(setup, 'socp', maps=maps).optimal:
            break
    else:
        pytest.fail('no load lost to the triangle in 40 draws')
    sol = solve(setup, 'tau-qp-adaptive', maps=maps)
    check_against_socp(setup, maps, sol)


def test_a_contact_in_pure_torsion_is_restored_in_the_first_round(allegro):
    """
    A contact in pure torsion is restored in the first round.

    A load for which one fingertip's optimum is pure torsion at f_min (f_t = 0, the apex of
    ||f_t||, where the cone has no gradient): the first round's candidate is already
    certified and inside the exact cone (without the apex rows it was not).
    """
    th = 2 * np.pi * 58 / 400
    w = allegro.external_wrench.copy()
    w[:3] = np.linalg.norm(w[:3]) * np.array([np.cos(th), 0.3 * np.sin(th), np.sin(th)])
    setup = dataclasses.replace(allegro, external_wrench=w)
    maps = setup.maps()
    exact = solve(setup, 'socp', maps=maps)
    ft = np.hypot(exact.wrenches[:, 0], exact.wrenches[:, 1])
    assert (ft / exact.wrenches[:, 2]).min() < 1e-8, 'the load no longer puts a contact at it'
    sol = solve(setup, 'tau-qp-adaptive', maps=maps)
    check_against_socp(setup, maps, sol)
    assert sol.bounds.source == 'refined' and sol.bounds.rounds == 1


def test_warm_start_follows_a_moving_grasp(allegro):
    """
    The node's case: a grasp moving by 1 mrad per cycle and a turning load.

    Warm, each cycle starts at the last answer's directions: every answer certified and
    bracketed.
    """
    rng = np.random.default_rng(3)
    refiner = Refiner(AdaptiveSettings(warm_start=True))
    q = allegro.q.copy()
    for k in range(25):
        q = q.copy()
        q[allegro.hand.idx_q] += rng.normal(scale=1e-3, size=allegro.hand.m)
        th = 2 * np.pi * k / 25
        w = allegro.external_wrench.copy()
        w[:3] = np.linalg.norm(w[:3]) * np.array([np.cos(th), 0.3 * np.sin(th), np.sin(th)])
        setup = dataclasses.replace(allegro, q=q, external_wrench=w)
        maps = setup.maps()
        sol = solve(setup, 'tau-qp-adaptive', maps=maps, refiner=refiner)
        check_against_socp(setup, maps, sol)
        assert sol.bounds.converged
    assert refiner.warm_solves == 24  # every cycle after the first
    assert refiner.warm_fallbacks <= 2


def test_without_daqp_the_papers_polygon_answers():
    """
    Without DAQP the method answers with the paper's N-gon, certified, and says why.

    A ROS distribution may lack DAQP (docs/ros2_control.md); nothing raises.
    """
    import subprocess
    import sys

    from conftest import ALLEGRO

    script = f"""
import sys
sys.modules["daqp"] = None  # any import of it now raises ImportError
from grasp_torque_opt import GraspSetup, solve
setup = GraspSetup.from_file({str(ALLEGRO)!r})
sol = solve(setup, "tau-qp-adaptive")
assert sol.optimal and sol.bounds.source == "polygon", sol.message
assert "DAQP, which is not installed" in sol.message, sol.message
print("ok")
"""
    done = subprocess.run([sys.executable, '-c', script], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0 and done.stdout.strip() == 'ok', done.stderr[-2000:]
