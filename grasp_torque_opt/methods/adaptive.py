# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Method ``tau-qp-adaptive``: the exact-cone optimum from QPs, with a certified gap.

docs/adaptive.md has the derivation and the measurements. All rounds of one
grasp share one DAQP workspace of fixed size, so each starts from the previous
round's active set. Each contact has the same rows in every round:

- two tangent facets, u . f_t/mu1 +- mz/mu2 <= fz, at the contact's current
  tangential direction u (round 0: two of the polygon's rows again);
- the circumscribed N0-gon's 2 N0 facets (the closure);
- fz >= f_min.

Every one of them holds on the whole exact cone, so the QP of these rows with the
tau-QP's objective is a relaxation (an outer approximation) of the exact SOCP.

Round 0 solves it with the polygon alone: its multipliers give a lower bound
(:func:`~grasp_torque_opt.core.bounds.dual_bound`) and its answer the first
directions. Round r >= 1:

1. step: tangent facets at the last point's directions and, in the objective,
   the curvature of ||f_t||/mu1 there across the direction, weighted by the
   contact's multiplier (a sequential-QP step on the exact cone, quadratically
   convergent where the polygon alone converges linearly);
2. candidate: two Gauss-Newton steps from the step's answer onto the exact-cone
   pieces that are active or violated, keeping the compatibility rows and the
   active normal and torque bounds; kept if certified and inside the exact cone
   and the torque limits (:data:`STRICT`): its norm is an upper bound;
3. bound from the step's multipliers with the facets turned to the candidate's
   directions, valid whenever its check passes;
4. only if the gap is still above tolerance: the relaxation with the facets at
   the candidate's directions (no curvature), solved warm; its multipliers
   give the bound, and they weight the next step's curvature.

It stops when sqrt(upper/lower) - 1 <= gap tolerance, or after ``max_rounds``.
The caller (:func:`grasp_torque_opt.methods.dispatch.solve`) falls back to the
paper's N-gon when no round gave a certified candidate.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
import math

from grasp_torque_opt.backends.daqp import DaqpSettings, DaqpWorkspace
from grasp_torque_opt.core.bounds import dual_bound, relaxation_duals
from grasp_torque_opt.core.certificate import Certificate, certify, DEFAULT_TOLERANCE
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
#: Round 0's polygon when refining: its directions are then close enough that one
#: round closes the gap for most grasps (bench/adaptive.py: 169 of 200 with 16
#: sides, fewer with 8; 24 or 32 sides cost as much in larger QPs as they save).
FIRST_SIDES = 16


@dataclass(frozen=True)
class AdaptiveSettings:
    """
    Settings of ``tau-qp-adaptive``.

    Attributes:
        gap_tolerance: stop when sqrt(upper/lower) - 1 is at most this [-].
        max_rounds: rounds after the first polygon (0: the circumscribed polygon
            only, whose bound then goes with the paper's N-gon answer).
        first_sides: sides of the circumscribed polygon of round 0 and of the
            closure. None: the scenario's ``polygon_sides`` when ``max_rounds`` is
            0 (the bound of the paper's own polygon), else at least
            :data:`FIRST_SIDES`.
        eps_abs: DAQP's primal tolerance.
        max_iter: DAQP's iteration cap per QP.
        warm_start: a grasp of the same size as the last one starts with a step
            at the last answer's directions and multipliers, skipping round 0,
            from the last QP's active set (a moving grasp, as in the node); if
            that gives no certified candidate, the grasp is solved cold.
    """

    gap_tolerance: float = 1e-3
    max_rounds: int = 4
    first_sides: int | None = None
    warm_start: bool = False
    eps_abs: float = DaqpSettings.primal_tol
    max_iter: int = DaqpSettings.iter_limit


@dataclass
class Refined:
    """
    What the rounds found for one grasp.

    Attributes:
        tau: the best certified candidate's torques [N m], or None.
        f: its stacked contact wrenches, shape (4p,), contact frames [N, N m].
        certificate: its certificate.
        lower: best checked lower bound on tau^T W tau (-inf: none).
        upper: the candidate's tau^T W tau (None without one).
        rounds: rounds run after round 0.
        qp_solves: QPs solved.
        iterations: DAQP iterations, all QPs.
        solve_time_s: time in DAQP [s].
        source: ``refined`` or ``circumscribed`` (round 0's own answer).
        message: how the rounds ended.
        outer_infeasible: round 0 (a relaxation) said infeasible.
    """

    tau: np.ndarray | None
    f: np.ndarray | None
    certificate: Certificate | None
    lower: float
    upper: float | None
    rounds: int
    qp_solves: int
    iterations: int
    solve_time_s: float
    source: str
    message: str
    outer_infeasible: bool = False


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


class Refiner:
    """
    Runs the rounds; reusable across grasps (one DAQP workspace, reset per grasp).

    Args:
        settings: the method's settings.
        workspace: the QP solver (a :class:`DaqpWorkspace`); a test may pass one
            with settings that make it fail.
    """

    def __init__(self, settings: AdaptiveSettings | None = None,
                 workspace: DaqpWorkspace | None = None) -> None:
        self.settings = settings or AdaptiveSettings()
        self.workspace = workspace or DaqpWorkspace(self.settings.eps_abs,
                                                    self.settings.max_iter)
        #: The last answer's (size key, directions, ||f_t||, defined, multipliers)
        #: for a warm start; None before one.
        self.last: tuple | None = None
        #: Grasps started warm, and those of them redone cold.
        self.warm_solves = self.warm_fallbacks = 0

    def refine(self, setup: GraspSetup, maps: GraspMaps, base: TauQP,
               tolerance: float = DEFAULT_TOLERANCE, deadline: float | None = None
               ) -> Refined:
        """
        Run round 0 and the refinement rounds on one grasp.

        Args:
            setup: the grasp.
            maps: its G and J.
            base: its tau-QP (:func:`~grasp_torque_opt.core.tau_qp.build_tau_qp`),
                whose decomposition every round reuses.
            tolerance: the certificate's tolerance, SI units.
            deadline: ``time.perf_counter()`` value by which the rounds stop [s]: each
                QP's iterations are fitted to the time left, and none starts past it
                (the rounds end with what they have). None: the caps alone.
        """
        rounds = _Rounds(self, setup, maps, base, tolerance)
        rounds.deadline = deadline
        return rounds.run()


class _Rounds:
    """
    One grasp's rounds (the arrays they share).

    Each numpy call costs about a microsecond here, so the pieces are written in few of
    them.
    """

    #: ``time.perf_counter()`` value by which every QP must stop (None: none).
    deadline: float | None = None

    def __init__(self, refiner: Refiner, setup: GraspSetup, maps: GraspMaps, base: TauQP,
                 tolerance: float) -> None:
        self.refiner, self.s = refiner, refiner.settings
        self.ws = refiner.workspace
        self.setup, self.maps, self.base, self.tolerance = setup, maps, base, tolerance
        fr = self.fr = setup.friction
        self.tau_min, self.tau_max = setup.tau_bounds
        self.W = np.asarray(setup.weights, dtype=float)
        p, m, n = maps.p, base.m, base.H.shape[0]
        self.p, self.m, self.n, self.n_eq = p, m, n, base.A.shape[0]
        self.MN = np.hstack((base.M2, base.N)).reshape(p, 4, n)  # f_i = f0_i + MN_i x
        self.f0 = (base.M1 @ base.w).reshape(p, 4)
        sides = self.s.first_sides
        if sides is None:
            sides = fr.sides if self.s.max_rounds == 0 else max(FIRST_SIDES, fr.sides)
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

    # -- pieces -----------------------------------------------------------------------

    def _qp(self, H: np.ndarray | None = None, g: np.ndarray | None = None):
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

    def _point(self, x: np.ndarray):
        """f, unit tangential directions, ||f_t|| and where a direction is defined."""
        f = self.f0 + np.matmul(self.MN, x)
        nt = np.hypot(f[:, 0], f[:, 1])
        ok = nt > 1e-9 * np.maximum(1.0, np.abs(f[:, 2]))
        return f, f[:, :2] / np.where(ok, nt, 1.0)[:, None], nt, ok

    def _turn(self, u: np.ndarray, ok: np.ndarray) -> None:
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

    def _curvature(self, u: np.ndarray, nt: np.ndarray, ok: np.ndarray,
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

    def _bound(self, lam: np.ndarray, y: np.ndarray) -> float:
        """Return the checked dual bound from these multipliers and the current rows."""
        eta, v = relaxation_duals(self.base, self.rows, lam, y)
        d = dual_bound(self.maps.G, self.maps.J, self.setup.external_wrench, self.fr,
                       self.W, self.tau_min, self.tau_max, eta, v, self.gt_pinv)
        return -math.inf if d is None else d

    def _restore(self, x: np.ndarray, lam: np.ndarray, box: np.ndarray):
        """
        Gauss-Newton steps (min-norm) onto the active or violated exact-cone pieces.

        Kept: the compatibility rows, the active torque bounds and f_min rows. A
        contact whose tangential force is below :data:`APEX` of its normal one is
        at the cone's apex in f_t, where ||f_t|| has no gradient: its f_t is
        driven to zero instead and its pieces are |mz|/mu2 <= fz alone. A second
        step only if the first left a piece outside (by more than STRICT/10).
        Each step's Gram matrix also gives, for one more right-hand side, the
        least-squares multipliers that make the point a KKT point of the exact
        problem with those rows (:meth:`_kkt_bound`). The per-contact work is in
        Python floats: for four contacts that is faster than numpy's calls.

        Returns:
            x, its _point (f, u, ||f_t||, ok), and the last step's rows on f with
            their least-squares multipliers (or None), for :meth:`_kkt_bound`.
        """
        fr, n = self.fr, self.n
        mu1, mu2, fmin = fr.mu1, fr.mu2, fr.min_normal_force
        act = (lam @ self.pieces > ACTIVE).tolist()  # (p, 2)
        at_fmin = np.flatnonzero(lam[:, -1] > ACTIVE)
        fixed = np.concatenate((self.base.A, -self.MN[at_fmin, 2],
                                self.eye[np.abs(box[:self.m]) > ACTIVE]))
        n_eq, n_fix = self.n_eq, fixed.shape[0]
        k_f = n_eq + at_fmin.size
        duals = None
        for step in range(3):
            f = self.f0 + np.matmul(self.MN, x)
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
                return x, self._point(x), duals
            rows = np.array([r for _, r in pieces]).reshape(-1, 4)
            owner = [i for i, _ in pieces]
            Jc = np.concatenate((fixed, self.MN[apex, :2].reshape(-1, n),
                                 np.matmul(rows[:, None, :], self.MN[owner])[:, 0, :]))
            k_a = n_fix + 2 * len(apex)
            rhs = np.zeros((Jc.shape[0], 2))
            rhs[n_eq:k_f, 0] = f[at_fmin, 2] - fmin - RESTORE_MARGIN
            rhs[n_fix:k_a, 0] = -f[apex, :2].ravel()
            rhs[k_a:, 0] = targets
            rhs[:, 1] = -Jc @ (self.base.H @ x)  # stationarity: H x + Jc^T theta = 0
            _, sol, info = dposv(Jc @ Jc.T, rhs)  # LAPACK directly: numpy's solve costs 10 us
            if info != 0:  # dependent rows (a degenerate active set): least squares
                sol = np.linalg.lstsq(Jc @ Jc.T, rhs, rcond=None)[0]
            x = x + Jc.T @ sol[:, 0]
            duals = (rows, owner, sol[:, 1], at_fmin, apex, (n_eq, k_f, n_fix, k_a))
        raise AssertionError('unreachable')

    def _kkt_bound(self, duals) -> float:
        """
        Return the dual bound from the multipliers that make the restored point a KKT point.

        Near the optimum they are the exact problem's own multipliers (the
        rows are the exact cone's gradients there), so no QP is needed for a
        tight bound; the check of :func:`~grasp_torque_opt.core.bounds.dual_bound`
        decides whether it holds.

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
        v = np.zeros((self.p, 4))
        np.add.at(v, owner, np.maximum(theta[k_a:], 0.0)[:, None] * inflated)
        v[at_fmin, 2] -= np.maximum(theta[n_eq:k_f], 0.0)
        v[apex, :2] += theta[n_fix:k_a].reshape(-1, 2)
        v = v.ravel()
        eta = v @ self.base.M2 + theta[:n_eq] @ self.base.A[:, :self.m]
        d = dual_bound(self.maps.G, self.maps.J, self.setup.external_wrench, self.fr, self.W,
                       self.tau_min, self.tau_max, eta, v, self.gt_pinv)
        return -math.inf if d is None else d

    def _candidate(self, x: np.ndarray, point=None):
        """(tau^T W tau, tau, f, certificate) if x is certified and strictly feasible."""
        f, _, nt, _ = self._point(x) if point is None else point
        fr = self.fr
        # The cheap test first: most rejected points are outside the cone.
        margin = f[:, 2] - nt / fr.mu1 - np.abs(f[:, 3]) * (1.0 / fr.mu2)
        if not (margin.min() >= -STRICT and f[:, 2].min() >= fr.min_normal_force - STRICT):
            return None
        tau, f = x[:self.m], f.ravel()
        cert = certify(self.maps.G, self.maps.J, self.setup.external_wrench, fr,
                       self.tau_min, self.tau_max, tau, f, self.tolerance)
        if not cert.ok or cert.cone > STRICT or cert.normal_force > STRICT or \
                cert.torque_limit > 0.0:
            return None
        return float(tau @ (self.W * tau)), tau, f, cert

    # -- the rounds -------------------------------------------------------------------

    def _key(self) -> tuple:
        """Return what a warm start needs to be the same: sizes and the cone."""
        return self.p, self.n, self.m, self.R, self.fr.mu1, self.fr.mu2

    def run(self) -> Refined:
        s = self.s
        last = self.refiner.last
        if s.warm_start and last is not None and last[0] == self._key():
            self.refiner.warm_solves += 1
            self._load(warm=True)
            out = self._rounds(-math.inf, None, 'refined', (None,) + last[1:4], last[4], 1)
            if out.tau is not None:
                return out
            self.refiner.warm_fallbacks += 1
            self.rows[:, :2] = self.spare  # the cold round 0's rows again
            self.C[:, :2] = np.matmul(self.rows[:, :2], self.MN)
            self.u[:, :2] = -np.matmul(self.rows[:, :2], self.f0[:, :, None])[:, :, 0]
        self._load(warm=False)
        raw, x, lam, y = self._qp()
        if x is None:
            return self._done(None, -math.inf, 0, 'circumscribed', f'round 0: {raw.message}',
                              raw.status == 'infeasible')
        point = self._point(x)
        best = self._candidate(x, point)
        lower = -math.inf
        # Round 0's bound is only needed if nothing better comes (rows change below).
        first = (self.rows.copy(), lam.copy(), y.copy())
        if best is not None or s.max_rounds == 0:
            lower = self._bound(lam, y)
        out = self._rounds(lower, best, 'circumscribed' if best is not None else 'refined',
                           point, np.maximum(lam[:, :-1], 0.0).sum(axis=1), 0, first)
        return out

    def _load(self, warm: bool) -> None:
        base = self.base
        self.ws.load(base.H, base.g, base.A, base.b, self.C.reshape(-1, self.n), self.u.ravel(),
                     base.l_box, base.u_box, semidefinite=self.n > self.m, warm=warm)

    def _rounds(self, lower: float, best, source: str, point, nu: np.ndarray, start: int,
                first=None) -> Refined:
        """
        Run the refinement rounds from a point's directions and multipliers nu.

        Args:
            lower: the best checked lower bound on tau^T W tau so far (-inf: none).
            best: the best certified candidate so far, as :meth:`_candidate` returns it,
                or None.
            source: what ``best`` came from (``refined`` or ``circumscribed``).
            point: the point whose directions the first step starts at, as :meth:`_point`
                returns it (its f is not used: None for a warm start).
            nu: per contact, the multipliers of its cone rows but the last, summed,
                shape (p,).
            start: 0 after round 0 (a gap check first), 1 for a warm start (a step
                first, at the last answer's directions).
            first: round 0's (rows, multipliers) for a bound if no round gives one.
        """
        base, s = self.base, self.s

        def gap() -> float:
            return math.sqrt(best[0] / lower) - 1.0 if best is not None and lower > 0 \
                else math.inf

        message, rounds, last_nu = 'max rounds', 0, None
        for rounds in range(1, max(s.max_rounds, start) + 1):
            if gap() <= s.gap_tolerance:
                rounds -= 1
                message = 'gap within tolerance'
                break
            _, u, nt, ok = point
            self._turn(u, ok)
            raw, xs, lam_s, y_s = self._qp(*self._curvature(u, nt, ok, nu))
            if xs is None:
                message = f'round {rounds} step: {raw.message}'
                break
            last_nu = np.maximum(lam_s[:, :-1], 0.0).sum(axis=1)
            xh, point, duals = self._restore(xs, lam_s, self.ws.multipliers[:self.n])
            if not np.all(np.isfinite(xh)):
                xh, point, duals = xs, self._point(xs), None
            cand = self._candidate(xh, point)
            if cand is not None and (best is None or cand[0] < best[0]):
                best, source = cand, 'refined'
                self.refiner.last = (self._key(), point[1], point[2], point[3], last_nu)
            if best is not None:  # without a candidate no bound closes the gap
                lower = max(lower, self._kkt_bound(duals))
                if gap() <= s.gap_tolerance:
                    message = 'gap within tolerance'
                    break
            # The restored point's own multipliers bound loosely while it is still a
            # step away (10 to 100 times its excess, measured): the relaxation with
            # the facets at its directions, solved warm, has exact multipliers.
            self._turn(point[1], point[3])
            raw, xl, lam_l, y_l = self._qp(base.H, base.g)
            if xl is None:
                message = f'round {rounds} relaxation: {raw.message}'
                break
            lower = max(lower, self._bound(lam_l, y_l))
            nu = np.maximum(lam_l[:, :-1], 0.0).sum(axis=1)
        else:
            if gap() <= s.gap_tolerance:
                message = 'gap within tolerance'
        if lower == -math.inf and first is not None:
            self.rows = first[0]
            lower = self._bound(first[1], first[2])
        return self._done(best, lower, rounds, source, message, False)

    def _done(self, best, lower: float, rounds: int, source: str, message: str,
              infeasible: bool) -> Refined:
        return Refined(tau=None if best is None else best[1],
                       f=None if best is None else best[2],
                       certificate=None if best is None else best[3], lower=lower,
                       upper=None if best is None else best[0], rounds=rounds,
                       qp_solves=self.qp_solves, iterations=self.iterations,
                       solve_time_s=self.solve_time, source=source, message=message,
                       outer_infeasible=infeasible)
