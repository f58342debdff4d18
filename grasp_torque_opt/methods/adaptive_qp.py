# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
One grasp's QP in ``tau-qp-adaptive``'s rounds: its rows, its solve, its bound.

docs/adaptive.md has the method; :mod:`~grasp_torque_opt.methods.adaptive` the
rounds' overview. Every QP of one grasp has the same rows per contact, each an outer
facet of the exact cone written on x = [tau; z] through f_i = f0_i + MN_i x: two
tangent slots, the inflated circumscribed polygon's rows and -fz <= -f_min. A round
turns the slots to new directions (:meth:`GraspQP.turn`) and may add the cone's
curvature to the objective (:meth:`GraspQP.curvature`).
"""

from __future__ import annotations

from functools import lru_cache
import math

from grasp_torque_opt.backends.daqp import DaqpWorkspace
from grasp_torque_opt.core.bounds import dual_bound, relaxation_duals
from grasp_torque_opt.core.exceptions import SolverError
from grasp_torque_opt.core.friction import circumscribed_rows
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.solution import RawResult
from grasp_torque_opt.core.tau_qp import TauQP
import numpy as np
from scipy.linalg.lapack import dposv

#: Relative inflation of every facet (core.friction.circumscribed_rows): the rows'
#: dual vectors then lie strictly inside the exact dual cone, so rounding cannot
#: push the bound's check out of it. Costs about 1e-7 of the bound.
INFLATION = 1e-7


@lru_cache(maxsize=32)
def _template(mu1: float, mu2: float, sides: int
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    One contact's rows in round 0, the spare tangent slots, and the rows' pieces.

    Rows: two tangent slots (here two of the polygon's rows again), the inflated
    circumscribed polygon's 2 N rows, -fz <= -f_min. Pieces, shape (R, 2): 1
    where a row bounds the +mz piece of the cone (column 0) or the -mz one.
    Read-only, shared.
    """
    closure = circumscribed_rows(mu1, mu2, sides, INFLATION)
    spare = closure[[0, sides]]
    rows = np.vstack((spare, closure, [0.0, 0.0, -1.0, 0.0]))
    pieces = np.zeros((rows.shape[0], 2))
    pieces[np.r_[0, 2:2 + sides], 0] = pieces[np.r_[1, 2 + sides:2 + 2 * sides], 1] = 1.0
    for a in (rows, spare, pieces):
        a.flags.writeable = False
    return rows, spare, pieces


@lru_cache(maxsize=32)
def _torque_rows(n: int, m: int) -> np.ndarray:
    """Rows of the identity on x = [tau; z] picking tau (read-only, shared)."""
    eye = np.eye(n)[:m]
    eye.flags.writeable = False
    return eye


class GraspQP:
    """
    One grasp's outer QP on one DAQP workspace (the arrays every round shares).

    Each numpy call costs about a microsecond here, so the pieces are written in few of
    them.

    Args:
        workspace: the QP solver, loaded once per grasp (:meth:`load`).
        setup: the grasp.
        maps: its G and J.
        base: its tau-QP (:func:`~grasp_torque_opt.core.tau_qp.build_tau_qp`).
        tolerance: the certificate's tolerance, SI units.
        sides: sides of the circumscribed polygon of round 0 and of the closure.
    """

    #: ``time.perf_counter()`` value by which every QP must stop (None: none).
    deadline: float | None = None

    def __init__(self, workspace: DaqpWorkspace, setup: GraspSetup, maps: GraspMaps,
                 base: TauQP, tolerance: float, sides: int) -> None:
        self.ws = workspace
        self.setup, self.maps, self.base, self.tolerance = setup, maps, base, tolerance
        fr = self.fr = setup.friction
        self.tau_min, self.tau_max = setup.tau_bounds
        self.W = np.asarray(setup.weights, dtype=float)
        p, m, n = maps.p, base.m, base.H.shape[0]
        self.p, self.m, self.n, self.n_eq = p, m, n, base.A.shape[0]
        self.MN = np.hstack((base.M2, base.N)).reshape(p, 4, n)  # f_i = f0_i + MN_i x
        self.f0 = (base.M1 @ base.w).reshape(p, 4)
        template, self.spare, self.pieces = _template(fr.mu1, fr.mu2, sides)
        self.R = template.shape[0]
        self.eye = _torque_rows(n, m)
        self.rows = np.empty((p,) + template.shape)
        self.rows[:] = template
        self.C = np.matmul(self.rows, self.MN)  # (p, R, n), the QP's C by contact
        self.u = -np.matmul(self.rows, self.f0[:, :, None])[:, :, 0]
        self.u[:, -1] -= fr.min_normal_force
        G = maps.G
        _, gt_pinv, info = dposv(G @ G.T, G)  # pinv(G^T) = (G G^T)^-1 G for G of rank 6
        self.gt_pinv = gt_pinv if info == 0 else np.linalg.pinv(G.T)
        self.slots = np.empty((p, 2, 4))
        self.slots[:, :, 2] = -1.0
        b = 1.0 / (fr.mu2 * (1.0 + INFLATION))
        self.slots[:, 0, 3], self.slots[:, 1, 3] = b, -b
        self.a = 1.0 / (fr.mu1 * (1.0 + INFLATION))
        self.qp_solves = self.iterations = 0
        self.solve_time = 0.0

    def key(self) -> tuple:
        """Return what a warm start needs to be the same: sizes and the cone."""
        return self.p, self.n, self.m, self.R, self.fr.mu1, self.fr.mu2

    def load(self, warm: bool) -> None:
        """Load the workspace with the tau-QP and the current rows (warm: keep its state)."""
        base = self.base
        self.ws.load(base.H, base.g, base.A, base.b, self.C.reshape(-1, self.n), self.u.ravel(),
                     base.l_box, base.u_box, semidefinite=self.n > self.m, warm=warm)

    def qp(self, H: np.ndarray | None = None, g: np.ndarray | None = None):
        """
        Solve with the current rows (and H, g): (raw, x, row multipliers, compat ones).

        A solver that raises is a failed round like any other (the rounds end with
        what they have; the caller's fallback answers if that is nothing).
        """
        try:
            raw = self.ws.solve(H, g, self.C.reshape(-1, self.n), self.u.ravel(),
                                deadline=self.deadline)
        except SolverError as e:
            raw = RawResult('error', None, 0, 0.0, str(e))
        self.qp_solves += 1
        self.iterations += raw.iterations
        self.solve_time += raw.solve_time_s
        if raw.status != 'solved' or raw.x is None or raw.x.shape != (self.n,):
            return raw, None, None, None
        lam = self.ws.multipliers
        n, n_eq = self.n, self.n_eq
        return raw, raw.x, lam[n + n_eq:].reshape(self.p, self.R), lam[n:n + n_eq]

    def point(self, x: np.ndarray):
        """f, unit tangential directions, ||f_t|| and where a direction is defined."""
        f = self.f0 + np.matmul(self.MN, x)
        nt = np.hypot(f[:, 0], f[:, 1])
        ok = nt > 1e-9 * np.maximum(1.0, np.abs(f[:, 2]))
        return f, f[:, :2] / np.where(ok, nt, 1.0)[:, None], nt, ok

    def turn(self, u: np.ndarray, ok: np.ndarray) -> None:
        """
        Set the tangent slots at the directions u (core.friction.tangent_rows).

        The spare rows go where no direction is defined.
        """
        slots = self.slots
        slots[:, :, :2] = self.a * u[:, None, :]
        if not ok.all():
            slots[~ok] = self.spare
        self.rows[:, :2] = slots
        self.C[:, :2] = np.matmul(slots, self.MN)
        self.u[:, :2] = -np.matmul(slots, self.f0[:, :, None])[:, :, 0]

    def reset_slots(self) -> None:
        """Put the spare rows back in the tangent slots: round 0's rows again."""
        self.rows[:, :2] = self.spare
        self.C[:, :2] = np.matmul(self.rows[:, :2], self.MN)
        self.u[:, :2] = -np.matmul(self.rows[:, :2], self.f0[:, :, None])[:, :, 0]

    def curvature(self, u: np.ndarray, nt: np.ndarray, ok: np.ndarray,
                  nu: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """
        H and g with 1/2 sum_i w_i (u_i_perp . f_t,i(x))^2, w_i = nu_i / (mu1 ||f_t,i||).

        That is the second-order term of ||f_t,i||/mu1 at the point (its Hessian
        there is (I - u u^T) / (mu1 ||f_t||)), nu_i >= 0 contact i's cone
        multiplier (both torsion signs); u_perp . f_t vanishes at the point itself.
        """
        w = np.where(ok, nu / (self.fr.mu1 * np.where(ok, nt, 1.0)), 0.0)
        perp = np.column_stack((-u[:, 1], u[:, 0]))
        Bp = np.einsum('pj,pjn->pn', perp, self.MN[:, :2, :])
        c = np.einsum('pj,pj->p', perp, self.f0[:, :2])
        return self.base.H + (Bp.T * w) @ Bp, Bp.T @ (w * c)

    def bound(self, lam: np.ndarray, y: np.ndarray) -> float:
        """Return the checked dual bound from these multipliers and the current rows."""
        eta, v = relaxation_duals(self.base, self.rows, lam, y)
        d = dual_bound(self.maps.G, self.maps.J, self.setup.external_wrench, self.fr,
                       self.W, self.tau_min, self.tau_max, eta, v, self.gt_pinv)
        return -math.inf if d is None else d
