# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The tau-space QP (docs/design.md section 2): build it as a plain dataclass.

With A = [G; J^T] (shape (6 + m) x 4p), every wrench that balances the load and
produces tau is

    f = M1 w + M2 tau + N z,    w = -w_ext,  [M1 M2] = pinv(A),  N = null(A),

provided [w; tau] lies in the range of A (the compatibility equalities
U_perp^T [w; tau] = 0, U_perp a basis of A's left null space). The QP over
x = [tau; z]:

    minimize    tau^T W tau
    subject to  S (M1 w + M2 tau + N z) <= b       linearized cones, f_z >= f_min
                U_perp^T [w; tau] = 0              compatibility
                tau_min <= tau <= tau_max          box constraints

z is not regularized: the optimal tau is unique (W > 0), the internal forces
need not be, and the certificate checks whichever f comes back. A "tiny"
regularization (1e-10 ||z||^2) made ProxSuite run into its iteration cap on
feasible planar grasps whose optimum sits on a torque bound; without it they
solve in 10 to 70 iterations.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
import math

from grasp_torque_opt.core.friction import friction_matrix
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.scenario import Friction
import numpy as np

#: Relative singular-value threshold for the rank of A.
RANK_RTOL = 1e-10
#: The QR path is taken when min |R_ii| exceeds this times max |R_ii|.
QR_RTOL = 1e-6
#: Distance kept inside the torque bounds [N m] (ProxSuite meets them to eps_abs).
BOX_MARGIN = 1e-8


@dataclass(frozen=True)
class TauQP:
    """
    A built tau-space QP: 1/2 x^T H x + g^T x, A x = b, C x <= u, box on x.

    Attributes:
        H: Hessian, shape (n, n), n = m + k.
        g: linear term, shape (n,).
        A: compatibility equalities, shape (n_eq, n).
        b: their right-hand side, shape (n_eq,).
        C: linearized cone rows in x, shape (n_in, n).
        u: their upper bound, shape (n_in,); no lower bound.
        l_box: lower bounds on x (-tau_max, then -inf for z), shape (n,).
        u_box: upper bounds on x, shape (n,).
        M1: f's dependence on w, shape (4p, 6).
        M2: f's dependence on tau, shape (4p, m).
        N: null-space basis of A (internal forces the joints cannot feel), shape (4p, k).
        w: the wrench the grasp must produce, -w_ext, shape (6,).
    """

    H: np.ndarray
    g: np.ndarray
    A: np.ndarray
    b: np.ndarray
    C: np.ndarray
    u: np.ndarray
    l_box: np.ndarray
    u_box: np.ndarray
    M1: np.ndarray
    M2: np.ndarray
    N: np.ndarray
    w: np.ndarray

    @property
    def m(self) -> int:
        """Return the number of joint torques."""
        return self.M2.shape[1]

    def split(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(tau, z) from x."""
        return x[:self.m], x[self.m:]

    def wrenches(self, x: np.ndarray) -> np.ndarray:
        """Stacked contact wrenches f = M1 w + M2 tau + N z, shape (4p,)."""
        tau, z = self.split(x)
        return self.M1 @ self.w + self.M2 @ tau + self.N @ z


def decompose(A_full: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    pinv(A), an orthonormal basis of null(A), and one of A's left null space.

    A full-column-rank A with at least as many rows as columns (the Allegro's
    four fingertips: 22 x 16) takes a Householder QR, A = [Q1 Q2] [R; 0]:
    pinv(A) = R^-1 Q1^T, null(A) = {0}, left null space Q2. Anything else, or
    an R whose diagonal spans more than 1/:data:`QR_RTOL`, takes the SVD with
    rank threshold :data:`RANK_RTOL`. The QR costs a fifth of the SVD here.

    Returns:
        (pinv, shape (cols, rows); N, shape (cols, k); U_perp, shape (rows, rows - rank)).
    """
    # SciPy's LAPACK on first use: its import (0.2 s) stays out of the planner's start-up.
    from scipy.linalg.lapack import dgeqrf, dorgqr, dtrtrs

    rows, cols = A_full.shape
    if rows >= cols > 0:
        qr, tau, _, info = dgeqrf(A_full)
        d = np.abs(qr.diagonal())
        if info == 0 and d.min() > QR_RTOL * d.max():
            padded = np.zeros((rows, rows))
            padded[:, :cols] = qr
            Q, _, info_q = dorgqr(padded, tau)
            pinv, info_r = dtrtrs(qr[:cols], Q[:, :cols].T)  # R X = Q1^T, R upper
            if info_q == 0 and info_r == 0:
                return pinv, np.zeros((cols, 0)), Q[:, cols:]
    U, sv, Vt = np.linalg.svd(A_full)
    r = int(np.sum(sv > RANK_RTOL * sv[0])) if sv.size else 0
    return (Vt[:r].T / sv[:r]) @ U[:, :r].T, Vt[r:].T, U[:, r:]


@lru_cache(maxsize=16)
def _hessian(weights: tuple[float, ...], k: int) -> np.ndarray:
    """2 diag(W) on tau, zero on z (read-only; the same every cycle)."""
    m = len(weights)
    H = np.zeros((m + k, m + k))
    H[:m, :m] = 2.0 * np.diag(weights)
    H.flags.writeable = False
    return H


def build_tau_qp(maps: GraspMaps, friction: Friction, external_wrench: np.ndarray,
                 tau_min: np.ndarray, tau_max: np.ndarray, weights: np.ndarray) -> TauQP:
    """
    Build the tau-space QP of one grasp.

    What does not change between cycles (S for the friction and contact count,
    H for the weights) is cached; the rest is a few array operations.

    Args:
        maps: G and J of the grasp.
        friction: friction model and polygon.
        external_wrench: w_ext, load on the object about c, base axes [N, N m].
        tau_min: lower torque bound, shape (m,) [N m].
        tau_max: upper torque bound, shape (m,) [N m]. The box keeps
            :data:`BOX_MARGIN` inside both, so that the solver's own tolerance
            never carries a torque across a limit.
        weights: W's diagonal, shape (m,).
    """
    G, J = maps.G, maps.J
    m = J.shape[1]
    pinv, N, U_perp = decompose(np.vstack((G, J.T)))
    M1, M2 = pinv[:, :6], pinv[:, 6:]
    w = -np.asarray(external_wrench, dtype=float)
    S, b_S = friction_matrix(maps.p, friction.mu1, friction.mu2, friction.sides,
                             friction.min_normal_force)
    k = N.shape[1]
    n_eq = U_perp.shape[1]
    C = S @ np.hstack((M2, N)) if k else S @ M2
    A = np.zeros((n_eq, m + k))
    A[:, :m] = U_perp[6:].T
    H = _hessian(tuple(np.asarray(weights, dtype=float).tolist()), k)
    l_box = np.full(m + k, -np.inf)
    u_box = np.full(m + k, np.inf)
    l_box[:m] = tau_min + BOX_MARGIN
    u_box[:m] = tau_max - BOX_MARGIN
    return TauQP(H=H, g=np.zeros(m + k), A=A, b=-U_perp[:6].T @ w, C=C,
                 u=b_S - S @ (M1 @ w), l_box=l_box, u_box=u_box, M1=M1, M2=M2, N=N, w=w)


def check_data(qp: TauQP) -> str:
    """
    Why a QP must not reach a solver ('' if it may): non-finite data, NaN or inverted bounds.

    One NaN in its data made ProxSuite run for 84 s uncapped and return NaN.
    """
    # One sum per array: NaN or Inf anywhere makes it non-finite (so does an
    # overflow of huge finite entries, which is refused as well).
    total = qp.H.sum() + qp.g.sum() + qp.A.sum() + qp.b.sum() + qp.C.sum() + qp.u.sum()
    if not math.isfinite(total):
        return 'QP data not finite'
    if not (qp.l_box <= qp.u_box).all():  # False for NaN as well
        return 'QP bounds NaN or inverted (lower > upper)'
    return ''
