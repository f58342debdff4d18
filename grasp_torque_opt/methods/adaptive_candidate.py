# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
A round's candidate in ``tau-qp-adaptive``: restored onto the exact cone, checked, bounded.

docs/adaptive.md, step 2 and 3 of a round. A step's answer lies outside the exact
cone by a second-order amount: :func:`restore` takes Gauss-Newton steps onto the cone
pieces that are active or violated, :func:`candidate` keeps the result only if it is
certified and strictly feasible (:data:`STRICT`), and :func:`kkt_bound` turns the
last step's least-squares multipliers into a checked lower bound.
"""

from __future__ import annotations

import math

from grasp_torque_opt.core.bounds import dual_bound
from grasp_torque_opt.core.certificate import certify
from grasp_torque_opt.methods.adaptive_qp import GraspQP, INFLATION
import numpy as np
from scipy.linalg.lapack import dposv

#: A candidate counts for the upper bound only if it violates the exact cone and the
#: normal bound by at most this [N] and no torque limit at all (the certificate's
#: own tolerance is wider; outer-polygon answers pass it while below the optimum).
STRICT = 1e-9
#: The restoration aims this far inside each cone piece and above f_min [N]: deep
#: enough that one Gauss-Newton step usually lands inside (its error is second
#: order), shallow enough to cost nothing (1e-8 N of normal force).
RESTORE_MARGIN = 1e-8
#: A multiplier above this marks its row active (for the restoration).
ACTIVE = 1e-12
#: A tangential force below this share of the normal one is at the cone's apex for
#: the restoration (zeroing it costs at most about this share of the objective).
APEX = 1e-6


def restore(qp: GraspQP, x: np.ndarray, lam: np.ndarray, box: np.ndarray):
    """
    Gauss-Newton steps (min-norm) onto the active or violated exact-cone pieces.

    Kept: the compatibility rows, the active torque bounds and f_min rows. A
    contact whose tangential force is below :data:`APEX` of its normal one is
    at the cone's apex in f_t, where ||f_t|| has no gradient: its f_t is
    driven to zero instead and its pieces are |mz|/mu2 <= fz alone. A second
    step only if the first left a piece outside (by more than STRICT/10).
    Each step's Gram matrix also gives, for one more right-hand side, the
    least-squares multipliers that make the point a KKT point of the exact
    problem with those rows (:func:`kkt_bound`). The per-contact work is in
    Python floats: for four contacts that is faster than numpy's calls.

    Args:
        qp: the grasp's QP.
        x: the step's answer, [tau; z].
        lam: its row multipliers, shape (p, R).
        box: its box multipliers, shape (n,).

    Returns:
        x, its point (f, u, ||f_t||, ok), and the last step's rows on f with
        their least-squares multipliers (or None), for :func:`kkt_bound`.
    """
    fr, n = qp.fr, qp.n
    mu1, mu2, fmin = fr.mu1, fr.mu2, fr.min_normal_force
    act = (lam @ qp.pieces > ACTIVE).tolist()  # (p, 2)
    at_fmin = np.flatnonzero(lam[:, -1] > ACTIVE)
    fixed = np.concatenate((qp.base.A, -qp.MN[at_fmin, 2],
                            qp.eye[np.abs(box[:qp.m]) > ACTIVE]))
    n_eq, n_fix = qp.n_eq, fixed.shape[0]
    k_f = n_eq + at_fmin.size
    duals = None
    for step in range(3):
        f = qp.f0 + np.matmul(qp.MN, x)
        pieces, targets, apex, worst = [], [], [], 0.0  # (contact, sign), gradient on f
        for i, (fx, fy, fz, mz) in enumerate(f.tolist()):
            nt = math.hypot(fx, fy)
            at_apex = nt <= APEX * max(1.0, abs(fz))
            ux, uy = (0.0, 0.0) if at_apex else (fx / (mu1 * nt), fy / (mu1 * nt))
            used = False
            for k, sign in ((0, 1.0), (1, -1.0)):
                c_t = sign * mz / mu2 - fz
                c = c_t + nt / mu1
                if act[i][k] or c > 0.0:
                    pieces.append((i, (ux, uy, -1.0, sign / mu2)))
                    targets.append(-RESTORE_MARGIN - (c_t if at_apex else c))
                    worst, used = max(worst, c), True
            if at_apex and used:
                apex.append(i)
        fz_min = f[at_fmin, 2].min(initial=np.inf)
        if step == 2 or (step and worst <= STRICT / 10 and fz_min >= fmin - STRICT / 10):
            return x, qp.point(x), duals
        rows = np.array([r for _, r in pieces]).reshape(-1, 4)
        owner = [i for i, _ in pieces]
        Jc = np.concatenate((fixed, qp.MN[apex, :2].reshape(-1, n),
                             np.matmul(rows[:, None, :], qp.MN[owner])[:, 0, :]))
        k_a = n_fix + 2 * len(apex)
        rhs = np.zeros((Jc.shape[0], 2))
        rhs[n_eq:k_f, 0] = f[at_fmin, 2] - fmin - RESTORE_MARGIN
        rhs[n_fix:k_a, 0] = -f[apex, :2].ravel()
        rhs[k_a:, 0] = targets
        rhs[:, 1] = -Jc @ (qp.base.H @ x)  # stationarity: H x + Jc^T theta = 0
        _, sol, info = dposv(Jc @ Jc.T, rhs)  # LAPACK directly: numpy's solve costs 10 us
        if info != 0:  # dependent rows (a degenerate active set): least squares
            sol = np.linalg.lstsq(Jc @ Jc.T, rhs, rcond=None)[0]
        x = x + Jc.T @ sol[:, 0]
        duals = (rows, owner, sol[:, 1], at_fmin, apex, (n_eq, k_f, n_fix, k_a))
    raise AssertionError('unreachable')


def kkt_bound(qp: GraspQP, duals) -> float:
    """
    Return the dual bound from the multipliers that make the restored point a KKT point.

    Near the optimum they are the exact problem's own multipliers (the
    rows are the exact cone's gradients there), so no QP is needed for a
    tight bound; the check of :func:`~grasp_torque_opt.core.bounds.dual_bound`
    decides whether it holds.

    Args:
        qp: the grasp's QP.
        duals: the last step's rows and multipliers, as :func:`restore` returns them,
            or None.

    Returns:
        The bound on tau^T W tau, or -inf.
    """
    if duals is None:
        return -math.inf
    rows, owner, theta, at_fmin, apex, (n_eq, k_f, n_fix, k_a) = duals
    # v = the contacts' multiplier vector: the pieces' rows (inflated: strictly
    # inside K*) and f_min's with multipliers >= 0, the apex rows f_t = 0 with
    # multipliers of either sign (as in core.bounds.relaxation_duals).
    inflated = rows * (1.0 / (1.0 + INFLATION))
    inflated[:, 2] = -1.0
    v = np.zeros((qp.p, 4))
    np.add.at(v, owner, np.maximum(theta[k_a:], 0.0)[:, None] * inflated)
    v[at_fmin, 2] -= np.maximum(theta[n_eq:k_f], 0.0)
    v[apex, :2] += theta[n_fix:k_a].reshape(-1, 2)
    v = v.ravel()
    eta = v @ qp.base.M2 + theta[:n_eq] @ qp.base.A[:, :qp.m]
    d = dual_bound(qp.maps.G, qp.maps.J, qp.setup.external_wrench, qp.fr, qp.W,
                   qp.tau_min, qp.tau_max, eta, v, qp.gt_pinv)
    return -math.inf if d is None else d


def candidate(qp: GraspQP, x: np.ndarray, point=None):
    """(tau^T W tau, tau, f, certificate) if x is certified and strictly feasible."""
    f, _, nt, _ = qp.point(x) if point is None else point
    fr = qp.fr
    # The cheap test first: most rejected points are outside the cone.
    margin = f[:, 2] - nt / fr.mu1 - np.abs(f[:, 3]) * (1.0 / fr.mu2)
    if not (margin.min() >= -STRICT and f[:, 2].min() >= fr.min_normal_force - STRICT):
        return None
    tau, f = x[:qp.m], f.ravel()
    cert = certify(qp.maps.G, qp.maps.J, qp.setup.external_wrench, fr,
                   qp.tau_min, qp.tau_max, tau, f, qp.tolerance)
    if not cert.ok or cert.cone > STRICT or cert.normal_force > STRICT or \
            cert.torque_limit > 0.0:
        return None
    return float(tau @ (qp.W * tau)), tau, f, cert
