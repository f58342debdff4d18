# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Checks written from the paper and docs/design.md, without the package's own builders."""

import numpy as np
from scipy.optimize import linprog


def polygon_rows(mu1: float, mu2: float, N: int, fmin: float) -> tuple[np.ndarray, np.ndarray]:
    """One contact's 2N paper inequalities and -fz <= -fmin, on [fx, fy, fz, mz]."""
    j = np.arange(1, N + 1)
    ang, ang1 = 2 * np.pi * j / N, 2 * np.pi * (j % N + 1) / N
    sN = np.sin(2 * np.pi / N)
    rows = [[mu2 * (np.sin(b) - np.sin(a)), mu2 * (np.cos(a) - np.cos(b)), -mu1 * mu2 * sN,
             sg * mu1 * sN] for sg in (1, -1) for a, b in zip(ang, ang1)]
    rows.append([0, 0, -1, 0])
    rhs = np.zeros(2 * N + 1)
    rhs[-1] = -fmin
    return np.array(rows, float), rhs


def lp_feasible(setup, maps) -> bool:
    """Run HiGHS on: G f + w_ext = 0, polygon cones, |J^T f + offset| <= limits."""
    fr = setup.friction
    S_i, b_i = polygon_rows(fr.mu1, fr.mu2, fr.sides, fr.min_normal_force)
    p = maps.p
    S = np.kron(np.eye(p), S_i)
    lim = setup.hand.torque_limits
    off = np.zeros(setup.hand.m) if setup.torque_offset is None else setup.torque_offset
    res = linprog(np.zeros(4 * p), A_ub=np.vstack((S, maps.J.T, -maps.J.T)),
                  b_ub=np.concatenate((np.tile(b_i, p), lim - off, lim + off)), A_eq=maps.G,
                  b_eq=-setup.external_wrench, bounds=(None, None), method='highs')
    assert res.status in (0, 2), res.message
    return res.status == 0


def assert_holds(setup, maps, tau, wrenches, tol=1e-6):
    """Equilibrium, tau = J^T f, exact cone, normal bound and limits (on tau + offset)."""
    fr = setup.friction
    force, moment = np.zeros(3), np.zeros(3)
    tau_from_f = np.zeros(setup.hand.m)
    for i, (frame, w) in enumerate(zip(maps.contacts, wrenches)):
        F = frame.rotation @ w[:3]
        force += F
        moment += np.cross(frame.position - maps.object_origin, F) + w[3] * frame.normal
        tau_from_f += maps.J[4 * i:4 * i + 4].T @ w
        assert np.hypot(w[0], w[1]) / fr.mu1 + abs(w[3]) / fr.mu2 <= w[2] + tol
        assert w[2] >= fr.min_normal_force - tol
    np.testing.assert_allclose(force + setup.external_wrench[:3], 0, atol=tol)
    np.testing.assert_allclose(moment + setup.external_wrench[3:], 0, atol=tol)
    np.testing.assert_allclose(tau, tau_from_f, atol=tol)
    off = 0.0 if setup.torque_offset is None else setup.torque_offset
    assert np.all(np.abs(tau + off) <= setup.hand.torque_limits + tol)


def _planned_mu(fr):
    """mu1, mu2 of the cone planned with the friction margin k: mu / (1 + k) (docs/planner.md)."""
    k = getattr(fr, 'margin', 0.0)
    return fr.mu1 / (1.0 + k), fr.mu2 / (1.0 + k)


def _f_space(setup, maps):
    """Polygon rows S f <= b of the planned cones and the torque bounds on J^T f (+ offset)."""
    fr = setup.friction
    mu1, mu2 = _planned_mu(fr)
    S_i, b_i = polygon_rows(mu1, mu2, fr.sides, fr.min_normal_force)
    p = maps.p
    S = np.kron(np.eye(p), S_i)
    lim = setup.hand.torque_limits
    off = np.zeros(setup.hand.m) if setup.torque_offset is None else setup.torque_offset
    return S, np.tile(b_i, p), lim, off


def lp_capacity(setup, maps, load):
    """
    Maximize alpha in contact-force space with HiGHS.

    The LP: max alpha with G f + alpha load = 0, the planned polygons and
    |J^T f + offset| <= limits. Returns (alpha, f) or (None, None).
    """
    S, b, lim, off = _f_space(setup, maps)
    nf = 4 * maps.p
    c = np.zeros(nf + 1)
    c[-1] = -1.0
    A_ub = np.vstack((np.hstack((S, np.zeros((S.shape[0], 1)))),
                      np.hstack((maps.J.T, np.zeros((setup.hand.m, 1)))),
                      np.hstack((-maps.J.T, np.zeros((setup.hand.m, 1))))))
    b_ub = np.concatenate((b, lim - off, lim + off))
    A_eq = np.hstack((maps.G, np.asarray(load, float)[:, None]))
    res = linprog(c, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=np.zeros(6),
                  bounds=[(None, None)] * nf + [(0, None)], method='highs')
    if res.status != 0:
        return None, None
    return float(res.x[-1]), res.x[:nf]


def lp_alpha_range(setup, maps, load, cap=1e6):
    """
    Return the interval (lo, hi) of alpha in [0, cap] with alpha load holdable, by HiGHS.

    Two LPs in contact-force space (min and max alpha, the planned polygons and the
    limits, as :func:`lp_capacity`); None when no alpha in [0, cap] is holdable. The
    holdable multiples of a load form an interval: the constraints are convex.
    """
    S, b, lim, off = _f_space(setup, maps)
    nf = 4 * maps.p
    pad = np.zeros((S.shape[0], 1))
    A_ub = np.vstack((np.hstack((S, pad)), np.hstack((maps.J.T, np.zeros((setup.hand.m, 1)))),
                      np.hstack((-maps.J.T, np.zeros((setup.hand.m, 1))))))
    b_ub = np.concatenate((b, lim - off, lim + off))
    A_eq = np.hstack((maps.G, np.asarray(load, float)[:, None]))
    ends = []
    for sign in (1.0, -1.0):
        c = np.zeros(nf + 1)
        c[-1] = sign
        res = linprog(c, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=np.zeros(6),
                      bounds=[(None, None)] * nf + [(0, cap)], method='highs')
        assert res.status in (0, 2), res.message
        if res.status == 2:
            return None
        ends.append(float(res.x[-1]))
    return tuple(ends)


def lp_minmax(setup, maps, weights=None):
    """
    Minimize t in contact-force space with HiGHS.

    The LP: min t with G f + w_ext = 0, the planned polygons, w_i |(J^T f)_i + offset_i|
    <= t limit_i and |J^T f + offset| <= limits. Returns t or None.
    """
    S, b, lim, off = _f_space(setup, maps)
    m = setup.hand.m
    w = np.ones(m) if weights is None else np.asarray(weights, float)
    nf = 4 * maps.p
    c = np.zeros(nf + 1)
    c[-1] = 1.0
    JT = maps.J.T
    zero = np.zeros((m, 1))
    A_ub = np.vstack((np.hstack((S, np.zeros((S.shape[0], 1)))),
                      np.hstack((JT, zero)), np.hstack((-JT, zero)),
                      np.hstack((w[:, None] * JT, -lim[:, None])),
                      np.hstack((-w[:, None] * JT, -lim[:, None]))))
    b_ub = np.concatenate((b, lim - off, lim + off, -w * off, w * off))
    res = linprog(c, A_ub=A_ub, b_ub=b_ub, A_eq=np.hstack((maps.G, np.zeros((6, 1)))),
                  b_eq=-setup.external_wrench, bounds=[(None, None)] * nf + [(0, None)],
                  method='highs')
    return float(res.x[-1]) if res.status == 0 else None


def polygon_slack(setup, wrench):
    """Largest value of one contact's planned polygon rows on its wrench (0 on the polygon)."""
    fr = setup.friction
    mu1, mu2 = _planned_mu(fr)
    S_i, _ = polygon_rows(mu1, mu2, fr.sides, fr.min_normal_force)
    return float((S_i[:-1] @ np.asarray(wrench, float)).max())
