# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Outer cones and the Lagrangian bound, against the exact cone and the independent SOCP."""

import dataclasses

from grasp_torque_opt.core.bounds import dual_bound, make_bounds
from grasp_torque_opt.core.friction import (
    circumscribed_rows,
    cone_margin,
    dual_cone_margin,
    tangent_rows,
)
from grasp_torque_opt.reference.exact_socp import solve_exact_socp
from independent import polygon_rows
import numpy as np
import pytest

MU1, MU2 = 0.5, 0.2


def exact_cone_points(rng, n, on_boundary=False):
    """Points of the exact cone sqrt(fx^2 + fy^2)/mu1 + |mz|/mu2 <= fz."""
    fz = rng.uniform(0.1, 3.0, n)
    share = rng.uniform(0.0, 1.0, n)  # of the cone spent on friction, the rest on torsion
    scale = np.ones(n) if on_boundary else rng.uniform(0.0, 1.0, n)
    th = rng.uniform(0.0, 2 * np.pi, n)
    ft = MU1 * fz * share * scale
    mz = MU2 * fz * (1 - share) * scale * rng.choice([-1.0, 1.0], n)
    return np.column_stack((ft * np.cos(th), ft * np.sin(th), fz, mz))


@pytest.mark.parametrize('N', [3, 4, 8, 16])
def test_circumscribed_polygon_is_the_papers_scaled_by_one_over_cos(N):
    """Each paper row (independent.polygon_rows) with its tangential part times cos(pi/N)."""
    paper = polygon_rows(MU1, MU2, N, 0.0)[0][:-1]
    paper = paper / -paper[:, 2:3]
    paper[:, :2] *= np.cos(np.pi / N)
    np.testing.assert_allclose(circumscribed_rows(MU1, MU2, N), paper, atol=1e-14)


@pytest.mark.parametrize('N', [3, 8, 16])
def test_outer_cones_contain_the_exact_cone_and_touch_it(N):
    rng = np.random.default_rng(N)
    f = exact_cone_points(rng, 2000)
    assert np.all(cone_margin(f, MU1, MU2) >= -1e-12)
    rows = circumscribed_rows(MU1, MU2, N)
    assert np.all(f @ rows.T <= 1e-12), 'an exact-cone point outside the circumscribed cone'
    u = rng.normal(size=(50, 2))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    tang = tangent_rows(MU1, MU2, u).reshape(-1, 4)
    assert np.all(f @ tang.T <= 1e-12)
    # Touch: the exact cone's boundary point along each direction meets its facet.
    fz = 2.0
    touch = np.column_stack((MU1 * fz * u, np.full(50, fz), np.zeros(50)))
    np.testing.assert_allclose(np.einsum('ki,ki->k', tangent_rows(MU1, MU2, u)[:, 0], touch),
                               0.0, atol=1e-12)
    # And the circumscribed polygon is strictly larger: its corner is outside the exact cone.
    corner = np.array([MU1 * fz / np.cos(np.pi / N), 0.0, fz, 0.0])
    assert np.all(rows @ corner <= 1e-12) and cone_margin(corner, MU1, MU2)[0] < -1e-3


def test_inflation_moves_every_facet_off_the_exact_cone():
    """
    Inflated, no facet touches the exact cone any more.

    The facets' dual vectors lie strictly inside the dual cone (docs/adaptive.md).
    """
    u = np.array([[1.0, 0.0], [0.6, 0.8]])
    touch = np.column_stack((MU1 * u, np.ones(2), np.zeros(2)))  # fz = 1, on the cone
    plain, inflated = tangent_rows(MU1, MU2, u)[:, 0], tangent_rows(MU1, MU2, u, 1e-3)[:, 0]
    np.testing.assert_allclose(np.einsum('ki,ki->k', plain, touch), 0.0, atol=1e-15)
    assert np.all(np.einsum('ki,ki->k', inflated, touch) < -1e-4)
    f = exact_cone_points(np.random.default_rng(1), 500, on_boundary=True)
    assert np.all(f @ circumscribed_rows(MU1, MU2, 8, 1e-3).T < 0.0)


def test_dual_cone_margin_is_the_dual_cone():
    """
    The margin's sign says whether s is in the dual cone.

    An s with margin >= 0 has s . f >= 0 on the whole exact cone; an s with margin < 0 has
    an extreme ray of the cone with s . f < 0.
    """
    rng = np.random.default_rng(3)
    f = exact_cone_points(rng, 4000, on_boundary=True)
    s = rng.normal(size=(400, 4))
    margin = dual_cone_margin(s, MU1, MU2)
    products = s @ f.T
    inside = margin >= 0
    assert inside.sum() > 20 and (~inside).sum() > 20
    assert np.all(products[inside] >= -1e-12)
    th = np.linspace(0.0, 2 * np.pi, 3600, endpoint=False)
    rays = np.vstack((np.column_stack((MU1 * np.cos(th), MU1 * np.sin(th), np.ones_like(th),
                                       np.zeros_like(th))),
                      [[0.0, 0.0, 1.0, MU2], [0.0, 0.0, 1.0, -MU2]]))
    assert np.all((s[~inside] @ rays.T).min(axis=1) < 0.0)


def random_dual_points(rng, maps, friction, k):
    """(eta, v) whose sigma = -v lies in K* + R+ e_z, for a grasp whose J is invertible."""
    p = maps.p
    out = []
    for _ in range(k):
        s = rng.normal(size=(p, 4))
        s[:, 2] = np.maximum(friction.mu1 * np.hypot(s[:, 0], s[:, 1]),
                             friction.mu2 * np.abs(s[:, 3])) + rng.uniform(0, 1, p)
        s *= rng.uniform(0.0, 0.2)
        y = rng.normal(scale=0.2, size=6)
        eta = np.linalg.solve(maps.J, maps.G.T @ y - s.ravel())
        out.append((eta, -s.ravel()))
    return out


def test_any_dual_feasible_point_bounds_the_socp_from_below(allegro):
    """
    The bound holds for any (eta, y) whose sigma is in K* + R+ e_z.

    Checked on random ones, against Clarabel's optimum of the exact SOCP
    (reference.exact_socp, no polygon in it).
    """
    maps = allegro.maps()
    assert np.linalg.matrix_rank(maps.J) == maps.J.shape[0]
    rng = np.random.default_rng(7)
    tmin, tmax = allegro.tau_bounds
    checked = 0
    for w_scale in (0.5, 1.0, 1.5):
        setup = dataclasses.replace(allegro, external_wrench=allegro.external_wrench * w_scale)
        raw = solve_exact_socp(maps, setup.friction, setup.external_wrench, tmin, tmax,
                               setup.weights)
        assert raw.status == 'solved'
        tau = maps.J.T @ raw.x[:4 * maps.p]
        E = float(tau @ (setup.weights * tau))
        for eta, v in random_dual_points(rng, maps, setup.friction, 40):
            d = dual_bound(maps.G, maps.J, setup.external_wrench, setup.friction,
                           setup.weights, tmin, tmax, eta, v)
            assert d is not None, 'a dual-feasible point was refused'
            assert d <= E + 1e-9
            checked += 1
    assert checked == 120


def test_a_point_outside_the_dual_cone_gives_no_bound(allegro):
    maps = allegro.maps()
    s = np.tile([1.0, 0.0, 0.1, 0.0], (maps.p, 1))  # mu1 ||s_t|| = 0.5 > s_z
    eta = np.linalg.solve(maps.J, -s.ravel())
    assert dual_bound(maps.G, maps.J, allegro.external_wrench, allegro.friction,
                      allegro.weights, *allegro.tau_bounds, eta, -s.ravel()) is None


def test_bounds_are_square_roots_of_the_objective():
    b = make_bounds(0.25, 0.2601, 1e-3, 2, 3, 'refined')
    assert b.lower == pytest.approx(0.5) and b.upper == pytest.approx(0.51)
    assert b.gap == pytest.approx(0.02) and not b.converged
    assert make_bounds(-np.inf, 0.26, 1e-3, 0, 1, 'polygon').gap is None
    d = make_bounds(0.25, 0.2500001, 1e-3, 1, 2, 'refined').as_dict()
    assert d['converged'] and set(d) == {'lower', 'upper', 'gap', 'tolerance', 'rounds',
                                         'qp_solves', 'source', 'converged'}
