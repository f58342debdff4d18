# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
DAQP (a dual active-set method) on the tau-QP, every answer KKT-checked.

DAQP is exact to its tolerances on small dense QPs. A positive semidefinite
Hessian (the internal-force variables z carry no cost) is handled by DAQP's
proximal-point iterations.
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass
from functools import cache
from importlib import metadata
import math
import time

from grasp_torque_opt.backends.proxsuite import ESTIMATE_DECAY, ProxSuiteSettings, size_factor
from grasp_torque_opt.core.exceptions import SolverError
from grasp_torque_opt.core.solution import RawResult
from grasp_torque_opt.core.tau_qp import check_data, TauQP
import numpy as np

#: DAQP's "infinite" bound.
DAQP_INF = 1e30
#: Seconds per DAQP iteration assumed before a solve of a size has measured it, for the
#: Allegro's tau-QP (about 2 us here), scaled by size_factor for others (32 contacts:
#: 50 to 90 us measured, up to 2900 iterations when it cycles).
ITERATION_S = 3e-6

#: Largest KKT violation (:func:`kkt_violation`) of an answer taken as optimal.
KKT_TOLERANCE = 1e-6


def kkt_violation(H: np.ndarray, g: np.ndarray, A: np.ndarray, lower: np.ndarray,
                  upper: np.ndarray, x: np.ndarray, lam: np.ndarray) -> float:
    """
    How far (x, lam) is from a KKT point of min 1/2 x'Hx + g'x, lower <= [x; A x] <= upper.

    Sign convention (DAQP's, bounds on x first): H x + g + [I A'] lam = 0,
    lam > 0 on an active upper bound, lam < 0 on an active lower one. An
    equality row has lower = upper, so its slack is zero whatever its sign.

    Returns:
        The largest of: the stationarity residual relative to the size of the
        gradient (at least 1), the primal infeasibility, and each row's
        multiplier times its slack (complementarity, which also catches a wrong
        sign).
    """
    n = x.size
    grad = H @ x + g
    residual = A.T @ lam[n:]
    residual[:n] += lam[:n]
    residual += grad
    Mx = np.empty(lower.size)
    Mx[:n] = x
    np.dot(A, x, out=Mx[n:])
    to_upper, to_lower = upper - Mx, Mx - lower
    # lam_i to_upper_i on a row held at its upper bound (lam_i > 0), -lam_i to_lower_i at
    # its lower one; the other product is <= 0 on a feasible point, so the larger is it.
    complementarity = np.maximum(lam * to_upper, -lam * to_lower)
    return max(float(np.abs(residual).max()) / max(1.0, float(np.abs(grad).max())),
               -float(np.minimum(to_upper, to_lower).min()), float(complementarity.max()))


#: The daqp releases whose C structs src/fast_cycle.hpp declares (for ``capacity_batch``
#: and the compiled cycle's DAQP solve).
DAQP_C_VERSIONS = ('0.11.0',)


@cache
def daqp_entry() -> tuple[int, int] | None:
    """
    Return the addresses of DAQP's ``daqp_quadprog`` and ``daqp_default_settings``.

    The daqp Python module's extension is DAQP's C library compiled in, its functions
    exported: the compiled batch and cycle call them there, the same code ``daqp.solve`` runs.
    None when the installed daqp is not a release whose structs the compiled batch
    declares (:data:`DAQP_C_VERSIONS`), or the functions are not found. Looked up once a
    process (the cycle asks whenever it decides whether its compiled twin applies).
    """
    try:
        import daqp

        if metadata.version('daqp') not in DAQP_C_VERSIONS:
            return None
        lib = ctypes.CDLL(daqp.__file__)
        return (ctypes.cast(lib.daqp_quadprog, ctypes.c_void_p).value,
                ctypes.cast(lib.daqp_default_settings, ctypes.c_void_p).value)
    except (ImportError, OSError, AttributeError, metadata.PackageNotFoundError):
        return None


@dataclass(frozen=True)
class DaqpSettings:
    """
    DAQP's settings used for the tau-QP.

    Attributes:
        primal_tol: DAQP's primal feasibility tolerance (``primal_tol``).
        iter_limit: cap on DAQP's iterations per solve (``iter_limit``; one cycle can
            never stall).
        eq_reduction: DAQP's ``eq_reduction``: -1 keeps the equalities as always-active
            rows, 0 lets DAQP decide, 1 eliminates them first. Off (-1) by default: on
            the Allegro's tau-QP (16 torques, 6 equalities, 68 cone rows) the automatic
            choice of DAQP's one-shot entry (the compiled cycle's) reduced them, and a
            warm setup took 8 us against 4 us, answers equal to 1e-13 (docs/design.md
            section 2.2). Set before the workspace's setup, which reads it.
    """

    primal_tol: float = ProxSuiteSettings.eps_abs
    iter_limit: int = ProxSuiteSettings.max_iter
    eq_reduction: int = -1

    @classmethod
    def from_proxsuite(cls, settings: ProxSuiteSettings) -> DaqpSettings:
        """Return DAQP's settings for a ProxSuiteSettings: its eps_abs and max_iter only."""
        return cls(primal_tol=settings.eps_abs, iter_limit=settings.max_iter)


class DaqpSolver:
    """
    DAQP on the tau-QP: bounds on x, then the equalities, then the cone rows.

    One DAQP workspace is kept per problem size. Every answer is checked for
    optimality (:func:`kkt_violation` with DAQP's multipliers, to
    :data:`KKT_TOLERANCE`) before it is returned as solved, on top of the
    caller's certificate.

    With ``warm_start``, a cycle starts from the previous cycle's active set
    (DAQP keeps it across updates); an answer that is not optimal by DAQP's
    flag and the KKT check is dropped and the QP solved again from a cold
    start within the same call; so is one that fails the caller's certificate
    (:func:`grasp_torque_opt.methods.dispatch.solve` asks again with ``cold=True``).
    ``warm_solves`` and ``fallbacks`` count them.

    Args:
        settings: DAQP's tolerance and iteration cap.
        warm_start: start from the previous active set.
    """

    name = 'daqp'

    def __init__(self, settings: DaqpSettings | None = None,
                 warm_start: bool = False) -> None:
        import daqp  # imported here: the core runs without the optional backends

        self._daqp = daqp
        self.settings = settings or DaqpSettings()
        self.warm_start = warm_start
        self.warm_solves = 0
        self.fallbacks = 0
        #: Whether the last answer came from a warm start (not redone cold).
        self.last_warm = False
        self._model = None
        self._dims: tuple[int, int, int] | None = None
        self._limit = self.settings.iter_limit
        self._iter_s = ITERATION_S
        self._keep: tuple = ()

    def solve(self, qp: TauQP, cold: bool = False, deadline: float | None = None
              ) -> RawResult:
        """
        Solve a built tau-QP (warm if enabled and verified, else cold).

        Args:
            qp: the QP.
            cold: start cold even with ``warm_start`` (the caller's redo of a warm
                answer that failed its certificate; counted in ``fallbacks``).
            deadline: ``time.perf_counter()`` value [s]: past it, no solve starts
                (an error result), and before it the iteration cap is lowered to
                the iterations that fit in the time left, at the measured time per
                iteration (DAQP 0.11's ``time_limit`` setting did not stop a plain
                QP here: docs/design.md section 2.2).
        """
        if cold and self.last_warm:
            self.fallbacks += 1
        self.last_warm = False
        if deadline is not None and time.perf_counter() >= deadline:
            return RawResult('error', None, 0, 0.0, 'time budget spent before DAQP started')
        why = check_data(qp)
        if why:
            return RawResult('error', None, 0, 0.0, why)
        n, n_eq, n_in = qp.H.shape[0], qp.A.shape[0], qp.C.shape[0]
        A = np.vstack((qp.A, qp.C))
        upper = np.concatenate((np.minimum(qp.u_box, DAQP_INF), qp.b, qp.u))
        lower = np.concatenate((np.maximum(qp.l_box, -DAQP_INF), qp.b, np.full(n_in, -DAQP_INF)))
        sense = np.zeros(n + n_eq + n_in, dtype=np.int32)
        sense[n:n + n_eq] = 5  # equality
        H = qp.H.copy()  # DAQP wants writable buffers; H is shared read-only
        if self._dims != (n, n_eq, n_in):
            self._iter_s = ITERATION_S * size_factor(qp)  # a new size: a guess
        limit = self.settings.iter_limit
        if deadline is not None:
            limit = min(limit, max(1, int((deadline - time.perf_counter()) / self._iter_s)))
        t0 = time.perf_counter()
        try:
            x, flag, info, iterations = self._run(qp, n, (n, n_eq, n_in), H, A, upper, lower,
                                                  sense, cold, limit)
        except RuntimeError as e:  # e.g. a failed setup: the next call starts anew
            self._dims = None
            raise SolverError(f'DAQP failed: {e}') from e
        if iterations:
            self._iter_s = max((time.perf_counter() - t0) / iterations,
                               ESTIMATE_DECAY * self._iter_s)
        if x is None:
            self._dims = None
            return RawResult('error', None, 0, time.perf_counter() - t0,
                             f'DAQP setup or update failed (exit flag {flag})')
        kkt = info['kkt']
        elapsed = time.perf_counter() - t0
        status = {1: 'solved', -1: 'infeasible'}.get(int(flag), 'error')
        message = f'DAQP exit flag {int(flag)}'
        if status == 'solved' and not kkt <= KKT_TOLERANCE:
            status, message = 'error', f'{message}, but KKT violated by {kkt:.3g}'
        return RawResult(status, np.asarray(x, dtype=float), iterations, elapsed, message)

    def _run(self, qp: TauQP, n: int, dims: tuple[int, int, int], H: np.ndarray,
             A: np.ndarray, upper: np.ndarray, lower: np.ndarray, sense: np.ndarray,
             cold: bool, limit: int):
        """
        Set up or update the workspace and solve, with at most ``limit`` iterations per solve.

        The solve is warm if enabled and not ``cold``, and verified.

        Returns:
            (x, flag, info with "kkt", iterations); x None if the setup failed.
        """
        if self._dims != dims:
            self._model = self._daqp.Model()
            s = self._model.settings  # before the setup, which reads eq_reduction
            s.update(primal_tol=self.settings.primal_tol, iter_limit=limit,
                     eps_prox=0.0 if n == qp.m else -1e-6,
                     eq_reduction=self.settings.eq_reduction)
            self._model.settings = s
            flag, _ = self._model.setup(H, qp.g, A, upper, lower, sense)
            if flag < 0:
                return None, flag, {}, 0
            self._dims = dims
            self._limit = limit
            warm = False
        else:
            warm = self.warm_start and not cold
            # Without sense, DAQP keeps the previous active set: a warm start.
            flag = self._model.update(H=H, f=qp.g, A=A, bupper=upper, blower=lower,
                                      sense=None if warm else sense)
            if flag is not None and flag < 0:
                return None, flag, {}, 0
        if limit != self._limit:  # a budget's cap, or back to max_iter
            s = self._model.settings
            s.update(iter_limit=limit)
            self._model.settings = s
            self._limit = limit
        self._keep = (H, qp.g, A, upper, lower, sense)  # buffers DAQP may point to
        x, _, flag, info = self._model.solve()
        iterations = int(info['iterations'])
        kkt = self._kkt(flag, H, qp.g, A, lower, upper, x, info)
        if warm:
            self.warm_solves += 1
            self.last_warm = kkt <= KKT_TOLERANCE
            if not self.last_warm:
                self.fallbacks += 1
                # Under a deadline the two solves share the cap fitted to it.
                rest = max(1, limit - iterations) if limit < self.settings.iter_limit else limit
                if rest != self._limit:
                    s = self._model.settings
                    s.update(iter_limit=rest)
                    self._model.settings = s
                    self._limit = rest
                self._model.update(sense=sense)  # the same data, cold
                x, _, flag, info = self._model.solve()
                iterations += int(info['iterations'])
                kkt = self._kkt(flag, H, qp.g, A, lower, upper, x, info)
        return x, flag, {**info, 'kkt': kkt}, iterations

    @staticmethod
    def _kkt(flag, H, g, A, lower, upper, x, info) -> float:
        """KKT violation of a DAQP answer that says optimal (inf otherwise)."""
        if int(flag) != 1:
            return float('inf')
        return kkt_violation(H, g, A, lower, upper, np.asarray(x), info['lam'])


class DaqpWorkspace:
    """
    One DAQP workspace for a sequence of QPs of one size, each started from the last.

    The QP: minimize 1/2 x'Hx + g'x subject to A_eq x = b_eq, C x <= u and
    l_box <= x <= u_box. :meth:`load` sets every datum (a new workspace when
    the size changes); :meth:`solve` replaces H, g, C and u, keeps the rest and
    starts from the previous active set unless ``cold``. This is the adaptive
    method's solver (:mod:`grasp_torque_opt.methods.adaptive`): its rounds keep
    the size, only their rows and curvature change, and it needs the
    multipliers. No answer is trusted here and none is KKT-checked: the method
    certifies every candidate against the exact cone and checks every bound it
    draws from the multipliers itself (docs/adaptive.md).

    Args:
        eps_abs: DAQP's primal tolerance.
        max_iter: DAQP's iteration cap (one QP can never stall).
    """

    name = 'daqp'

    def __init__(self, eps_abs: float = DaqpSettings.primal_tol,
                 max_iter: int = DaqpSettings.iter_limit) -> None:
        import daqp  # imported here: the core runs without the optional backends

        self._daqp = daqp
        self.eps_abs, self.max_iter = eps_abs, max_iter
        self._model = None
        self._dims: tuple[int, int, int, bool] | None = None
        self._limit = max_iter
        self._iter_s = ITERATION_S
        #: The last answer's multipliers, DAQP's order and sign: bounds on x, then
        #: A_eq's rows, then C's; > 0 on an active upper bound. None before one.
        self.multipliers: np.ndarray | None = None

    def load(self, H: np.ndarray, g: np.ndarray, A_eq: np.ndarray, b_eq: np.ndarray,
             C: np.ndarray, u: np.ndarray, l_box: np.ndarray, u_box: np.ndarray,
             semidefinite: bool, warm: bool = False) -> None:
        """
        Set every datum of the QP; the next solve starts cold unless ``warm``.

        Args:
            H: the Hessian, shape (n, n).
            g: the linear cost, shape (n,).
            A_eq: the equality rows, shape (n_eq, n).
            b_eq: their right-hand side, shape (n_eq,).
            C: the inequality rows (upper bounds only), shape (n_in, n).
            u: their upper bounds, shape (n_in,).
            l_box: lower bounds on x, shape (n,) (may be -inf).
            u_box: upper bounds on x, shape (n,) (may be inf).
            semidefinite: H may be singular (DAQP's proximal-point iterations on).
            warm: a QP of the same size may start from the last one's active set.
        """
        n, n_eq, n_in = H.shape[0], A_eq.shape[0], C.shape[0]
        self._A = np.empty((n_eq + n_in, n))
        self._A[:n_eq], self._A[n_eq:] = A_eq, C
        self._upper = np.empty(n + n_eq + n_in)
        self._lower = np.empty(n + n_eq + n_in)
        self._upper[:n], self._lower[:n] = np.minimum(u_box, DAQP_INF), np.maximum(l_box,
                                                                                   -DAQP_INF)
        self._upper[n:n + n_eq] = self._lower[n:n + n_eq] = b_eq
        self._upper[n + n_eq:], self._lower[n + n_eq:] = u, -DAQP_INF
        self._sense = np.zeros(n + n_eq + n_in, dtype=np.int32)
        self._sense[n:n + n_eq] = 5  # equality
        self._H, self._g = np.array(H, dtype=float), np.array(g, dtype=float)
        self._n_eq = n_eq
        dims = (n, n_eq, n_in, semidefinite)
        if self._dims != dims:
            self._model, self._dims = None, dims
            self._iter_s = ITERATION_S * max(1.0, n * (n + n_eq + n_in) / (16 * 144))
        self._cold = not warm

    def solve(self, H: np.ndarray | None = None, g: np.ndarray | None = None,
              C: np.ndarray | None = None, u: np.ndarray | None = None,
              cold: bool = False, deadline: float | None = None) -> RawResult:
        """
        Solve with the given H, g, C, u (None: keep the last), warm unless ``cold``.

        Args:
            deadline: ``time.perf_counter()`` value [s]: past it no solve starts, and
                before it the iteration cap is the iterations that fit (as
                :class:`DaqpSolver`'s).

        Returns:
            The raw result; ``multipliers`` holds its multipliers when solved.

        Raises:
            SolverError: DAQP raised (chained); the next solve starts anew.
        """
        self.multipliers = None
        limit = self.max_iter
        if deadline is not None:
            left = deadline - time.perf_counter()
            if left <= 0.0:
                return RawResult('error', None, 0, 0.0, 'time budget spent before DAQP started')
            limit = min(limit, max(1, int(left / self._iter_s)))
        n_eq = self._n_eq
        n = self._H.shape[0]
        for new, old in ((H, self._H), (g, self._g)):
            if new is not None:
                np.copyto(old, new)
        if C is not None:
            self._A[n_eq:] = C
        if u is not None:
            self._upper[n + n_eq:] = u
        # One sum per array: NaN or Inf anywhere makes it non-finite.
        if not math.isfinite(self._H.sum() + self._g.sum() + self._A.sum()
                             + self._upper[n:].sum()):
            return RawResult('error', None, 0, 0.0, 'QP data not finite')
        t0 = time.perf_counter()
        try:
            if self._model is None:
                self._model = self._daqp.Model()
                flag, _ = self._model.setup(self._H, self._g, self._A, self._upper,
                                            self._lower, self._sense)
                if flag < 0:
                    self._model = None
                    return RawResult('error', None, 0, time.perf_counter() - t0,
                                     f'DAQP setup failed (exit flag {flag})')
                s = self._model.settings
                s.update(primal_tol=self.eps_abs, iter_limit=limit,
                         eps_prox=-1e-6 if self._dims[3] else 0.0)
                self._model.settings = s
                self._limit = limit
            else:
                # Without sense, DAQP keeps the previous active set: a warm start.
                flag = self._model.update(H=self._H, f=self._g, A=self._A, bupper=self._upper,
                                          blower=self._lower,
                                          sense=self._sense if cold or self._cold else None)
                if flag is not None and flag < 0:
                    self._model = None
                    return RawResult('error', None, 0, time.perf_counter() - t0,
                                     f'DAQP update failed (exit flag {flag})')
                if limit != self._limit:  # a budget's cap, or back to max_iter
                    s = self._model.settings
                    s.update(iter_limit=limit)
                    self._model.settings = s
                    self._limit = limit
            x, _, flag, info = self._model.solve()
        except RuntimeError as e:
            self._model = None
            raise SolverError(f'DAQP failed: {e}') from e
        self._cold = False
        elapsed = time.perf_counter() - t0
        if int(info['iterations']):
            self._iter_s = max(elapsed / int(info['iterations']), ESTIMATE_DECAY * self._iter_s)
        status = {1: 'solved', -1: 'infeasible'}.get(int(flag), 'error')
        if status == 'solved':
            self.multipliers = np.asarray(info['lam'], dtype=float)
        return RawResult(status, np.asarray(x, dtype=float), int(info['iterations']), elapsed,
                         f'DAQP exit flag {int(flag)}')
