# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Certified bounds on the exact-cone optimum (docs/adaptive.md).

The exact problem (the SOCP of :mod:`grasp_torque_opt.reference.exact_socp`):

    minimize    tau^T W tau
    subject to  tau = J^T f,  G f + w_ext = 0,  tau_min <= tau <= tau_max,
                f_i in K_i = {fz >= ||f_t||/mu1 + |mz|/mu2},  fz_i >= f_min.

Lagrangian bound: for any eta (shape (m,)) and y (shape (6,)), let
sigma = G^T y - J eta (shape (4p,), one 4-vector per contact). If every
sigma_i = kappa_i + rho_i e_z with kappa_i in the dual cone K_i* and rho_i >= 0,
then for every feasible (tau, f)

    tau^T W tau >= tau^T W tau + eta^T (tau - J^T f) + y^T (G f + w_ext)
                   - sum_i kappa_i^T f_i - sum_i rho_i (fz_i - f_min)
                >= sum_j min_{t in [tau_min_j, tau_max_j]} (W_j t^2 + eta_j t)
                   + y^T w_ext + f_min sum_i rho_i,

(the first line adds terms that are zero or <= 0 there; the f terms cancel by
the choice of sigma), so the right-hand side is a lower bound on the exact
optimum, whatever solver produced eta and y. It is checked here, not assumed:
the best rho_i is the margin of sigma_i in K_i*
(:func:`~grasp_torque_opt.core.friction.dual_cone_margin`) and the bound is
refused if a margin is negative beyond rounding. A relaxation's multipliers
(an outer polygon's QP) give sigma in K* by construction and a bound as high as
that relaxation's optimum; the fmin part can lift it above.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
import math

from grasp_torque_opt.core.friction import dual_cone_margin
from grasp_torque_opt.core.scenario import Friction
from grasp_torque_opt.core.tau_qp import TauQP
import numpy as np

#: A dual-cone margin down to -ROUNDING * max(1, max |sigma|) is rounding: a contact
#: whose rows are all slack has sigma = 0 up to 1e-16 on either side.
ROUNDING = 1e-12


@dataclass(frozen=True)
class Bounds:
    """
    Where the returned torque stands against the exact-cone optimum.

    Every figure is the weighted torque norm sqrt(tau^T W tau) [N m] (||tau||_2
    for W = I), the square root of the objective that every method minimizes.

    Attributes:
        lower: a certified lower bound on the exact optimum (a checked
            Lagrangian bound), or None if none was found.
        upper: the returned torque's norm, certified in the exact cone (so no
            exact solver can do better than ``lower`` nor need more than this).
        gap: upper / lower - 1 [-], or None without a lower bound.
        tolerance: the gap the method aimed at [-].
        rounds: refinement rounds run (0: the first polygon only).
        qp_solves: QPs solved.
        source: what the torque came from: ``refined`` (a refined round,
            certified), ``circumscribed`` (the outer polygon's own answer,
            certified) or ``polygon`` (the paper's N-gon, the fallback).
    """

    lower: float | None
    upper: float | None
    gap: float | None
    tolerance: float
    rounds: int
    qp_solves: int
    source: str

    @property
    def converged(self) -> bool:
        """Return True when the certified gap is within the tolerance."""
        return self.gap is not None and self.gap <= self.tolerance

    def as_dict(self) -> dict:
        """Plain-data form (JSON), with ``converged``."""
        return {**asdict(self), 'converged': self.converged}


def make_bounds(lower_objective: float, upper_objective: float | None, tolerance: float,
                rounds: int, qp_solves: int, source: str) -> Bounds:
    """
    Bounds from objective values (tau^T W tau): their square roots and the gap.

    Args:
        lower_objective: the best lower bound on tau^T W tau (-inf or <= 0: none).
        upper_objective: the returned torque's tau^T W tau (None: no torque).
        tolerance: the gap tolerance (:attr:`Bounds.tolerance`).
        rounds: refinement rounds run (:attr:`Bounds.rounds`).
        qp_solves: QPs solved.
        source: what the torque came from (:attr:`Bounds.source`).
    """
    lower = math.sqrt(lower_objective) if lower_objective > 0.0 else None
    upper = None if upper_objective is None else math.sqrt(max(upper_objective, 0.0))
    gap = None if lower is None or upper is None else upper / lower - 1.0
    return Bounds(lower, upper, gap, tolerance, rounds, qp_solves, source)


def relaxation_duals(qp: TauQP, rows: np.ndarray, row_multipliers: np.ndarray,
                     compat_multipliers: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """
    (eta, v) from the multipliers of a tau-QP whose cone rows are ``rows``.

    With rows a_r f_i <= b_r (f = M1 w + M2 tau + N z) and multipliers lam_r >= 0,
    the QP's stationarity in tau reads 2 W tau + mu_box + eta = 0 with
    eta = sum_r lam_r (a_r M2_i) + A_tau^T y (y the compatibility rows'
    multipliers), and v = sum_r lam_r a_r is the contacts' multiplier vector.

    Args:
        qp: the QP's decomposition (M2, A).
        rows: shape (p, R, 4), each contact's R rows on [fx, fy, fz, mz].
        row_multipliers: shape (p, R), >= 0 (negatives from rounding are dropped).
        compat_multipliers: shape (n_eq,), the compatibility rows' multipliers.

    Returns:
        eta, shape (m,), and v, shape (4p,).
    """
    v = np.matmul(np.maximum(row_multipliers, 0.0)[:, None, :], rows).ravel()
    return v @ qp.M2 + compat_multipliers @ qp.A[:, :qp.m], v


def dual_bound(G: np.ndarray, J: np.ndarray, external_wrench: np.ndarray, friction: Friction,
               weights: np.ndarray, tau_min: np.ndarray, tau_max: np.ndarray,
               eta: np.ndarray, v: np.ndarray,
               gt_pinv: np.ndarray | None = None) -> float | None:
    """
    Compute a checked lower bound on the exact optimum of tau^T W tau (module docstring).

    y is the least-squares solution of G^T y = J eta - v, so that sigma is -v
    where the relaxation's stationarity holds exactly; the bound's validity does
    not rest on that: sigma is recomputed from (eta, y) and checked.

    Args:
        G: grasp matrix, shape (6, 4p).
        J: hand Jacobian, shape (4p, m).
        external_wrench: w_ext, shape (6,) [N, N m].
        friction: mu1, mu2, f_min.
        weights: W's diagonal, shape (m,).
        tau_min: lower torque bound of the exact problem, shape (m,) [N m].
        tau_max: upper torque bound, shape (m,) [N m].
        eta: shape (m,); v: shape (4p,) (:func:`relaxation_duals`).
        gt_pinv: pinv(G^T), shape (6, 4p), if already computed (a caller
            bounding one grasp several times computes it once).

    Returns:
        The bound on tau^T W tau [N^2 m^2], or None when some sigma_i lies outside
        K_i* + R+ e_z beyond rounding (no bound from these multipliers).
    """
    j_eta = J @ eta
    rhs = j_eta - v
    y = np.linalg.lstsq(G.T, rhs, rcond=None)[0] if gt_pinv is None else gt_pinv @ rhs
    sigma = (G.T @ y - j_eta).reshape(-1, 4)
    rho = dual_cone_margin(sigma, friction.mu1, friction.mu2)
    worst = float(rho.min())
    if not math.isfinite(worst + float(y.sum())) or \
            worst < -ROUNDING * max(1.0, float(np.abs(sigma).max())):
        return None
    t = np.clip(-eta / (2.0 * weights), tau_min, tau_max)
    return float(np.sum(weights * t * t + eta * t) + y @ external_wrench
                 + friction.min_normal_force * np.maximum(rho, 0.0).sum())
