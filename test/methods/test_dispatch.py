# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Every method, certified; infeasible verdicts confirmed by an independent LP."""

import dataclasses
import re

from grasp_torque_opt.backends import make_solver
from grasp_torque_opt.methods.dispatch import METHODS, solve
from independent import assert_holds, lp_feasible
import numpy as np
import pytest

CASES = ['planar', 'hyperstatic', 'allegro']


@pytest.mark.parametrize('method', METHODS)
@pytest.mark.parametrize('name', CASES)
def test_every_result_holds_the_load(name, method, request):
    setup = request.getfixturevalue(name)
    maps = setup.maps()
    sol = solve(setup, method, maps=maps)
    assert sol.status == 'optimal', sol.message
    assert sol.certificate.ok and sol.tau.shape == (setup.hand.m,)
    assert_holds(setup, maps, sol.tau, sol.wrenches)


@pytest.mark.parametrize('name', CASES)
def test_exact_methods_agree(name, request):
    """SOCP (interior point) and SLSQP reach the same exact-cone optimum."""
    setup = request.getfixturevalue(name)
    maps = setup.maps()
    socp, nlp = solve(setup, 'socp', maps=maps), solve(setup, 'nlp', maps=maps)
    assert socp.torque_norm == pytest.approx(nlp.torque_norm, rel=1e-4)


def test_heavy_load_is_infeasible_and_the_lp_agrees(planar):
    heavy = dataclasses.replace(planar, external_wrench=planar.external_wrench * 200.0)
    maps = heavy.maps()
    for method in ('tau-qp', 'force-qp', 'socp'):
        sol = solve(heavy, method, maps=maps)
        assert sol.status == 'infeasible', (method, sol.message)
        assert sol.tau is None and sol.wrenches is None
    assert not lp_feasible(heavy, maps)
    assert lp_feasible(planar, planar.maps())


def test_torque_limits_alone_make_it_infeasible(allegro):
    weak = dataclasses.replace(allegro, hand=dataclasses.replace(
        allegro.hand, torque_limits=np.full(allegro.hand.m, 1e-3)))
    maps = weak.maps()
    assert not lp_feasible(weak, maps)
    assert solve(weak, maps=maps).status == 'infeasible'


def test_min_normal_force_is_respected(planar):
    free = solve(planar)
    fmin = 1.5 * float(np.max(free.wrenches[:, 2]))
    squeeze = dataclasses.replace(planar, friction=dataclasses.replace(
        planar.friction, min_normal_force=fmin))
    sol = solve(squeeze)
    assert sol.status == 'optimal'
    assert np.all(sol.wrenches[:, 2] >= fmin - 1e-6)
    assert sol.torque_norm > free.torque_norm


def test_a_result_that_fails_its_certificate_is_not_returned(planar):
    """An impossible tolerance: the solver succeeds, the certificate does not, no torque."""
    sol = solve(planar, tolerance=-1.0)
    assert sol.status == 'failed'
    assert sol.tau is None and sol.wrenches is None
    assert 'certificate failed' in sol.message and 'LP finds the load holdable' in sol.message


def test_unknown_method_is_refused(planar):
    with pytest.raises(ValueError,
                       match='method must be one of tau-qp, tau-qp-adaptive, force-qp, socp, nlp'):
        solve(planar, 'lp')


@pytest.mark.parametrize('name', ['planar', 'allegro'])
@pytest.mark.parametrize('N', [3, 4, 6, 8, 16, 32])
def test_polygon_optimum_is_sandwiched_by_exact_cones(name, N, request):
    """
    The polygon's optimum lies between two exact (SOCP) optima.

    The inscribed N-gon contains the exact cone with mu1 cos(pi/N) and is inside the one
    with mu1.
    """
    setup = request.getfixturevalue(name)
    fr = dataclasses.replace(setup.friction, sides=N)
    shrunk = dataclasses.replace(fr, mu1=fr.mu1 * np.cos(np.pi / N))
    maps = setup.maps()
    ours = solve(dataclasses.replace(setup, friction=fr), maps=maps)
    lower = solve(dataclasses.replace(setup, friction=fr), 'socp', maps=maps)
    upper = solve(dataclasses.replace(setup, friction=shrunk), 'socp', maps=maps)
    assert ours.optimal and lower.optimal and upper.optimal
    assert lower.torque_norm - 1e-7 <= ours.torque_norm <= upper.torque_norm + 1e-7


def test_nested_polygons_never_increase_the_optimum(planar):
    """Vertices at 2 pi j / N: the 2N-gon contains the N-gon."""
    norms = [solve(dataclasses.replace(planar, friction=dataclasses.replace(
        planar.friction, sides=N))).torque_norm for N in (4, 8, 16, 32)]
    assert all(b <= a + 1e-9 for a, b in zip(norms, norms[1:]))


@pytest.mark.parametrize('joint', range(4))
@pytest.mark.parametrize('scale', [-2.5, -1.5, 1.5, 2.5])
def test_torque_offset_beyond_the_limit(planar, joint, scale):
    """An offset past a limit: the verdict (optimal or infeasible) matches the LP's."""
    off = np.zeros(4)
    off[joint] = scale * planar.hand.torque_limits[joint]
    shifted = dataclasses.replace(planar, torque_offset=off)
    maps = shifted.maps()
    sol = solve(shifted, maps=maps)
    assert sol.status == ('optimal' if lp_feasible(shifted, maps) else 'infeasible')
    if sol.optimal:
        assert_holds(shifted, maps, sol.tau, sol.wrenches)


def test_torque_offset_shifts_the_limits(planar):
    """With an offset (gravity compensation), the limits bound tau + offset."""
    free = solve(planar)
    lim = planar.hand.torque_limits
    # Push joint 1 towards its limit: only 1e-3 N m of headroom remains for tau_1.
    off = np.zeros(4)
    off[0] = -np.sign(free.tau[0]) * (lim[0] - abs(free.tau[0]) - 1e-3)
    shifted = dataclasses.replace(planar, torque_offset=off)
    sol = solve(shifted)
    assert sol.status == 'optimal'
    assert_holds(shifted, shifted.maps(), sol.tau, sol.wrenches)
    np.testing.assert_allclose(sol.tau, free.tau, atol=1e-7)


class ShortAnswer:
    """A solver that claims success with one variable too few (a broken backend)."""

    name = 'short'

    def solve(self, qp):
        raw = make_solver('daqp').solve(qp)
        return dataclasses.replace(raw, x=raw.x[:-1])


@pytest.mark.parametrize('name', ['planar', 'allegro'])
def test_an_answer_of_the_wrong_size_is_an_error_and_the_fallback_answers(name, request):
    setup = request.getfixturevalue(name)
    alone = solve(setup, solver=ShortAnswer())
    assert alone.status == 'failed' and alone.tau is None
    got, n = map(int, re.search(r'x has shape \((\d+),\) for (\d+) variables',
                                alone.message).groups())
    assert got == n - 1 and n >= setup.hand.m
    rescued = solve(setup, solver=ShortAnswer(), fallback=make_solver('daqp'))
    assert rescued.optimal and rescued.backend == 'daqp'
    assert 'fallback after' in rescued.message and 'x has shape' in rescued.message
    assert_holds(setup, setup.maps(), rescued.tau, rescued.wrenches)
