# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The linearized cone S against the paper's inequalities and the exact cone."""

from grasp_torque_opt.core.friction import (
    cone_margin,
    cone_rows,
    contact_block,
    friction_matrix,
    friction_usage,
)
import numpy as np
import pytest


def paper_rows(mu1, mu2, N):
    """Write out the paper's 2N inequalities term by term (Section 1)."""
    s = lambda j: np.sin(2 * np.pi * j / N)  # noqa: E731 -- the paper's s_j, as it writes it
    c = lambda j: np.cos(2 * np.pi * j / N)  # noqa: E731 -- the paper's c_j, as it writes it
    sN = np.sin(2 * np.pi / N)
    rows = []
    for sign in (+1, -1):
        for j in range(1, N + 1):
            jn = j + 1 if j < N else 1  # s_{N+1} = s_1
            rows.append([mu2 * (s(jn) - s(j)), mu2 * (c(j) - c(jn)), -mu1 * mu2 * sN,
                         sign * mu1 * sN])
    return np.array(rows)


@pytest.mark.parametrize('N', [3, 4, 5, 8, 13, 32])
@pytest.mark.parametrize('mu1,mu2', [(0.5, 0.2), (1.2, 0.01), (0.1, 0.5)])
def test_rows_are_the_papers_inequalities(N, mu1, mu2):
    np.testing.assert_allclose(cone_rows(mu1, mu2, N), paper_rows(mu1, mu2, N), atol=1e-15)


@pytest.mark.parametrize('N', [3, 4, 6, 8, 16])
def test_every_vertex_lies_on_the_exact_cone(N):
    mu1, mu2 = 0.5, 0.2
    S = cone_rows(mu1, mu2, N)
    angles = 2 * np.pi * np.arange(1, N + 1) / N
    fz = 2.0
    ring = [[mu1 * fz * np.cos(a), mu1 * fz * np.sin(a), fz, 0.0] for a in angles]
    apexes = [[0.0, 0.0, fz, mu2 * fz], [0.0, 0.0, fz, -mu2 * fz]]
    for v in np.array(ring + apexes):
        assert np.all(S @ v <= 1e-12)
        assert np.sum(np.abs(S @ v) < 1e-12) >= 2, 'a vertex is where two or more facets meet'
        assert cone_margin(v[None], mu1, mu2)[0] == pytest.approx(0.0, abs=1e-12)


def test_polygon_is_inside_the_exact_cone():
    rng = np.random.default_rng(0)
    mu1, mu2 = 0.7, 0.05
    S = cone_rows(mu1, mu2, 5)
    f = rng.normal(size=(20000, 4))
    f[:, 2] = 3.0 * np.abs(f[:, 2])
    f[:, 3] *= 0.1
    inside = np.all(f @ S.T <= 0.0, axis=1)
    assert inside.sum() > 100
    assert np.all(cone_margin(f[inside], mu1, mu2) >= -1e-12)


def test_polygon_converges_to_the_cone():
    # Points just inside the exact cone, in every direction, are inside for large N.
    mu1, mu2 = 0.5, 0.2
    a = np.linspace(0, 2 * np.pi, 50)
    f = np.column_stack((0.99 * mu1 * np.cos(a), 0.99 * mu1 * np.sin(a), np.ones_like(a),
                         np.zeros_like(a)))
    assert np.all(f @ cone_rows(mu1, mu2, 64).T <= 0)
    assert not np.all(f @ cone_rows(mu1, mu2, 3).T <= 0)


def test_normal_bound_and_block_structure():
    S_i, b_i = contact_block(0.5, 0.2, 4, 1.5)
    assert S_i.shape == (9, 4) and b_i[-1] == -1.5
    np.testing.assert_array_equal(S_i[-1], [0, 0, -1, 0])
    S, b = friction_matrix(3, 0.5, 0.2, 4, 1.5)
    assert S.shape == ((2 * 4 + 1) * 3, 12)  # the paper's (2Np + p) x 4p
    np.testing.assert_array_equal(S[9:18, 4:8], S_i)
    assert np.all(S[9:18, :4] == 0)


def test_fewer_than_three_sides_is_refused():
    with pytest.raises(ValueError, match='polygon_sides must be >= 3'):
        cone_rows(0.5, 0.2, 2)


def test_friction_usage():
    u = friction_usage(np.array([[0.3, 0.4, 2.0, 0.1]]), 0.5, 0.2)
    np.testing.assert_allclose(u, [[0.5, 0.25]])
    assert np.isinf(friction_usage(np.array([[0.1, 0.0, 0.0, 0.0]]), 0.5, 0.2)[0, 0])
