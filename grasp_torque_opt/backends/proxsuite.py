# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""ProxSuite's dense ProxQP on the tau-QP: the design's default backend."""

from __future__ import annotations

from dataclasses import dataclass
import time

from grasp_torque_opt.core.exceptions import SolverError
from grasp_torque_opt.core.solution import RawResult
from grasp_torque_opt.core.tau_qp import check_data, TauQP
import numpy as np
import proxsuite

#: Largest KKT violation (:func:`kkt_violation`) of a warm answer taken as optimal.
KKT_TOLERANCE = 1e-6


def kkt_violation(qp: TauQP, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> float:
    """
    How far ProxSuite's (x, y, z) is from a KKT point of the tau-QP.

    ProxSuite's convention: H x + g + A'y + C'z_C + z_box = 0, z = [z_C; z_box],
    z_i > 0 on an active upper bound, < 0 on an active lower one. The cone rows
    have no lower bound, so z_C < 0 is wrong however small the slack: that is
    how a warm start that stopped on a stale active set shows (seen on a drifting
    Allegro sequence: ProxSuite said solved, the certificate held, tau was 1.7e-3
    N m off the optimum, and the most negative z_C was 14% of the largest).

    Returns:
        The largest of: the stationarity residual relative to the gradient (at
        least 1); the cone rows' wrong-signed multipliers, the box multipliers on
        an infinite bound, and every multiplier times its slack, each relative
        to the largest multiplier (at least 1); the primal infeasibility.
    """
    n_in = qp.C.shape[0]
    z_C, z_box = z[:n_in], z[n_in:]
    grad = qp.H @ x + qp.g
    residual = grad + qp.C.T @ z_C + z_box
    if qp.A.shape[0]:
        residual += qp.A.T @ y
    slack = qp.u - qp.C @ x
    to_upper, to_lower = qp.u_box - x, x - qp.l_box
    finite_up, finite_lo = np.isfinite(to_upper), np.isfinite(to_lower)
    scale = max(1.0, float(np.abs(z).max(initial=0.0)))
    dual = max(-float(z_C.min(initial=0.0)),
               float(np.abs(z_box[~(finite_up & finite_lo)]).max(initial=0.0)),
               float(np.abs(z_C * slack).max(initial=0.0)),
               float((np.maximum(z_box, 0.0) * np.where(finite_up, to_upper, 0.0)).max()),
               float((np.maximum(-z_box, 0.0) * np.where(finite_lo, to_lower, 0.0)).max()))
    primal = max(-float(slack.min(initial=0.0)), -float(to_upper.min()),
                 -float(to_lower.min()),
                 float(np.abs(qp.A @ x - qp.b).max(initial=0.0)) if qp.A.shape[0] else 0.0)
    return max(float(np.abs(residual).max()) / max(1.0, float(np.abs(grad).max())),
               dual / scale, primal)


#: Seconds per ProxSuite inner iteration assumed before a solve of a size has measured
#: it, for the Allegro's tau-QP (7 to 25 us per inner iteration here, setup included);
#: scaled by :func:`size_factor` for others (32 contacts: 150 to 420 us measured).
INNER_ITERATION_S = 25e-6


def size_factor(qp: TauQP) -> float:
    """
    Return how much more a dense solver's iteration costs on ``qp`` than on the Allegro's.

    The Allegro's four-fingertip tau-QP has 16 variables and 144 rows; the factor is
    n (n + rows) against that, at least 1.
    """
    n = qp.H.shape[0]
    return max(1.0, n * (n + qp.A.shape[0] + qp.C.shape[0]) / (16 * 144))


#: Each solve's measured time per inner iteration replaces the estimate if larger; a
#: smaller one lowers it by at most this factor per solve (a slow solve is remembered).
ESTIMATE_DECAY = 0.9
#: Fewest outer iterations in a slice cut short by ``max_slice_s``: each continuation
#: restarts ProxSuite's inner tolerances, and slices of 1 to 3 outer iterations never
#: converged on Allegro QPs that one call solves in 24 to 47 (10 always did, here).
MIN_SLICE_OUTER = 20


@dataclass(frozen=True)
class ProxSuiteSettings:
    """
    ProxSuite dense settings used for the tau-QP.

    Attributes:
        eps_abs: absolute stopping tolerance.
        eps_rel: relative stopping tolerance.
        max_iter: cap on outer iterations (one cycle can never stall). Feasible
            grasps take 10 to 70; on loads 20 times too heavy for 60 Allegro
            grasps, the worst solve took 248 ms with caps 1000/200 and 51 ms
            with 200/50, all 200 feasible grasps still certified.
        max_iter_in: cap on inner iterations.
        eps_primal_inf: primal infeasibility threshold. ProxSuite's default (1e-4)
            declared the feasible Allegro grasp of config/allegro_right.yaml
            PRIMAL_INFEASIBLE after 24 iterations (M2 = pinv(A) has entries of
            1/sigma_min ~ 150 there); 1e-8 still did so on a rotating load and on
            3 of 600 bench grasps (N = 6, 12, 32) that DAQP, quadprog and
            Clarabel solve; 1e-12 solves all of them.

        hessian_type: ProxSuite's ``HessianType``: ``Diagonal`` (H = 2 diag(W) on
            tau and 0 on z, as :func:`build_tau_qp` builds it; a QP whose H is
            not diagonal is solved as ``Dense``) or ``Dense``.
        dense_backend: ProxSuite's ``DenseBackend``: ``PrimalDualLDLT``,
            ``PrimalLDLT`` or ``Automatic``. Diagonal with PrimalDualLDLT was
            the fastest of 54 variants tuned by bench/solvers.py on a separate
            grasp set (about 0.7 times the time of Dense/Automatic, the same
            optimum to 1e-7 N m on the 200 bench grasps).

        preconditioner: ``first`` computes ProxSuite's preconditioner on the
            first problem of a size and keeps it through every ``update``
            (ProxSuite's default for ``update``; it also keeps a warm start's
            scaling consistent), ``every`` recomputes it in each ``update``,
            ``off`` never computes it.

    The duality gap is checked as well, to ``eps_abs``: without that check
    ProxSuite stopped up to 2e-6 (relative) above Clarabel's optimum.
    """

    eps_abs: float = 1e-9
    eps_rel: float = 0.0
    max_iter: int = 200
    max_iter_in: int = 50
    eps_primal_inf: float = 1e-12
    hessian_type: str = 'Diagonal'
    dense_backend: str = 'PrimalDualLDLT'
    preconditioner: str = 'first'


class TauQPSolver:
    """
    ProxSuite dense solver for tau-QPs, allocated once per problem size.

    A time budget (``deadline`` of :meth:`solve`) is kept by ProxSuite's own
    iteration cap: ProxSuite has no wall-clock limit, so the solve runs in
    slices of outer iterations, each sized from the measured time per inner
    iteration so that even at ``max_iter_in`` inner iterations per outer one it
    ends by the deadline (or after ``max_slice_s``, but never fewer than
    :data:`MIN_SLICE_OUTER`), continued from the slice's result
    (``WARM_START_WITH_PREVIOUS_RESULT``) until ProxSuite stops by itself,
    ``max_iter`` outer iterations are done, or the deadline has passed. The
    deadline is overrun by at most one outer iteration. A solve that fits in
    its first slice (every feasible bench grasp under the node's budget) is
    one ProxSuite call, as without a budget. docs/design.md section 2.2.

    With ``warm_start``, each solve on a QP of the same size starts from the
    previous result (``WARM_START_WITH_PREVIOUS_RESULT``; data replaced with
    ``update``, preconditioner kept). A warm answer that ProxSuite does not call
    solved, or that fails the KKT check (:func:`kkt_violation`, to
    :data:`KKT_TOLERANCE`), is redone cold within the same call; one that fails the caller's
    certificate is redone when the caller asks again with ``cold=True``
    (:func:`grasp_torque_opt.methods.dispatch.solve` does). ``warm_solves`` and
    ``fallbacks`` count them, as for DAQP.

    Args:
        settings: ProxSuite's settings.
        warm_start: start from the previous result.
        max_slice_s: longest ProxSuite call under a deadline [s] (None: up to the
            deadline). ProxSuite holds Python's interpreter lock while it runs: a
            solver in a worker thread (the node's service) keeps its slices short
            so that the control loop's thread gets the lock between them.
    """

    name = 'proxsuite'

    def __init__(self, settings: ProxSuiteSettings | None = None,
                 warm_start: bool = False, max_slice_s: float | None = None) -> None:
        self.settings = settings or ProxSuiteSettings()
        self.warm_start = warm_start
        self.max_slice_s = max_slice_s
        #: Solves stopped by their deadline.
        self.timeouts = 0
        self._inner_s = INNER_ITERATION_S
        self.warm_solves = 0
        self.fallbacks = 0
        #: Whether the last answer came from a warm start (not redone cold).
        self.last_warm = False
        self._qp = None
        self._dims: tuple | None = None

    def _hessian_type(self, H: np.ndarray) -> str:
        """Return the settings' Hessian type, unless H is not diagonal (then ``Dense``)."""
        if self.settings.hessian_type == 'Diagonal' and \
                np.count_nonzero(H) != np.count_nonzero(np.diagonal(H)):
            return 'Dense'
        return self.settings.hessian_type

    def solve(self, qp: TauQP, cold: bool = False, deadline: float | None = None
              ) -> RawResult:
        """
        Solve a built tau-QP (warm if enabled and the size is unchanged, else cold).

        Args:
            qp: the QP.
            cold: start cold even with ``warm_start`` (the caller's redo of a warm
                answer that failed its certificate; counted in ``fallbacks``).
            deadline: ``time.perf_counter()`` value by which to stop [s] (None: no
                budget, only the iteration caps). A solve stopped by it is an
                error result ("time budget ...").

        Returns:
            The raw result; the caller certifies it.

        Raises:
            SolverError: ProxSuite raised (chained); the next call starts anew.
        """
        if cold and self.last_warm:
            self.fallbacks += 1
        self.last_warm = False
        why = check_data(qp)
        if why:
            return RawResult('error', None, 0, 0.0, why)
        n, n_eq, n_in = qp.H.shape[0], qp.A.shape[0], qp.C.shape[0]
        data = {'H': qp.H, 'g': qp.g, 'A': qp.A if n_eq else None,
                'b': qp.b if n_eq else None, 'C': qp.C, 'l': np.full(n_in, -np.inf),
                'u': qp.u, 'l_box': qp.l_box, 'u_box': qp.u_box}
        dims = (n, n_eq, n_in, self._hessian_type(qp.H))
        guess = proxsuite.proxqp.InitialGuess
        t0 = time.perf_counter()
        try:
            if self._dims != dims:
                self._inner_s = INNER_ITERATION_S * size_factor(qp)  # a new size: a guess
                self._init(dims, data)
                warm = False
            else:
                warm = self.warm_start and not cold
                self._qp.settings.initial_guess = (guess.WARM_START_WITH_PREVIOUS_RESULT if warm
                                                   else guess.NO_INITIAL_GUESS)
                self._qp.update(**data,
                                update_preconditioner=self.settings.preconditioner == 'every')
            iterations, stopped = self._solve_until(deadline)
            if warm:
                self.warm_solves += 1
                r = self._qp.results
                self.last_warm = r.info.status == proxsuite.proxqp.QPSolverOutput.PROXQP_SOLVED \
                    and kkt_violation(qp, r.x, r.y, r.z) <= KKT_TOLERANCE
                if not self.last_warm and not stopped:  # the same data, cold
                    self.fallbacks += 1
                    self._qp.settings.initial_guess = guess.NO_INITIAL_GUESS
                    more, stopped = self._solve_until(deadline)
                    iterations += more
        except (RuntimeError, ValueError, TypeError) as e:
            self._dims = None
            raise SolverError(f'ProxSuite failed: {e}') from e
        elapsed = time.perf_counter() - t0
        info = self._qp.results.info
        if stopped:
            self.timeouts += 1
            x = np.array(self._qp.results.x) if iterations else None  # else the last QP's
            return RawResult('error', x, iterations, elapsed,
                             f'time budget spent after {iterations} iterations '
                             f'({1e3 * elapsed:.1f} ms)')
        out = proxsuite.proxqp.QPSolverOutput
        status = {out.PROXQP_SOLVED: 'solved',
                  out.PROXQP_PRIMAL_INFEASIBLE: 'infeasible'}.get(info.status, 'error')
        return RawResult(status, np.array(self._qp.results.x), iterations, elapsed,
                         str(info.status).rsplit('.', 1)[-1])

    def _solve_until(self, deadline: float | None) -> tuple[int, bool]:
        """
        Run ProxSuite's solve from the initial guess set, within ``deadline`` if given.

        Returns:
            (inner iterations, whether the deadline stopped it before ProxSuite did).
        """
        qp = self._qp
        if deadline is None:
            qp.solve()
            return int(qp.results.info.iter), False
        s = qp.settings
        cap = self.settings.max_iter
        max_reached = proxsuite.proxqp.QPSolverOutput.PROXQP_MAX_ITER_REACHED
        inner = outer = 0
        capped = False  # ProxSuite's max_iter lowered for a slice (each write costs)
        try:
            while True:
                left = deadline - time.perf_counter()
                if left <= 0.0:
                    return inner, True
                # The worst an outer iteration can take: max_iter_in inner ones.
                per_outer = self.settings.max_iter_in * self._inner_s
                k = max(1, int(left / per_outer))
                if self.max_slice_s is not None:
                    k = min(k, max(MIN_SLICE_OUTER, int(self.max_slice_s / per_outer)))
                k = min(cap - outer, k)
                if k != cap or capped:
                    s.max_iter, capped = k, True
                t0 = time.perf_counter()
                qp.solve()
                info = qp.results.info
                iters = int(info.iter)
                inner += iters
                outer += int(info.iter_ext)
                per_inner = (time.perf_counter() - t0) / max(1, iters)
                self._inner_s = max(per_inner, ESTIMATE_DECAY * self._inner_s)
                if info.status != max_reached or outer >= cap:
                    return inner, False
                # Continue from where the slice stopped (ProxSuite keeps its iterate,
                # multipliers and penalty parameters with this guess).
                s.initial_guess = proxsuite.proxqp.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT
        finally:
            if capped:
                s.max_iter = cap

    def _init(self, dims: tuple, data: dict) -> None:
        """Make a new ProxSuite QP for this problem size, set up with the settings and ``data``."""
        dense = proxsuite.proxqp.dense
        self._qp = dense.QP(*dims[:3], True, hessian_type=getattr(dense.HessianType, dims[3]),
                            dense_backend=getattr(dense.DenseBackend,
                                                  self.settings.dense_backend))
        s = self._qp.settings
        s.eps_abs = self.settings.eps_abs
        s.eps_rel = self.settings.eps_rel
        s.max_iter = self.settings.max_iter
        s.max_iter_in = self.settings.max_iter_in
        s.eps_primal_inf = self.settings.eps_primal_inf
        s.check_duality_gap = True
        s.eps_duality_gap_abs = self.settings.eps_abs
        s.eps_duality_gap_rel = 0.0
        s.initial_guess = proxsuite.proxqp.InitialGuess.NO_INITIAL_GUESS
        self._qp.init(**data, compute_preconditioner=self.settings.preconditioner != 'off')
        self._dims = dims
