"""ProxSuite's dense ProxQP on the tau-QP: the design's default backend."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import proxsuite

from grasp_torque_opt.core.exceptions import SolverError
from grasp_torque_opt.core.solution import RawResult
from grasp_torque_opt.core.tau_qp import TauQP, check_data


@dataclass(frozen=True)
class ProxSuiteSettings:
    """ProxSuite dense settings used for the tau-QP.

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

    The duality gap is checked as well, to ``eps_abs``: without that check
    ProxSuite stopped up to 2e-6 (relative) above Clarabel's optimum.
    """

    eps_abs: float = 1e-9
    eps_rel: float = 0.0
    max_iter: int = 200
    max_iter_in: int = 50
    eps_primal_inf: float = 1e-12
    hessian_type: str = "Diagonal"
    dense_backend: str = "PrimalDualLDLT"



class TauQPSolver:
    """ProxSuite dense solver for tau-QPs, allocated once per problem size."""

    name = "proxsuite"

    def __init__(self, settings: ProxSuiteSettings | None = None) -> None:
        self.settings = settings or ProxSuiteSettings()
        self._qp = None
        self._dims: tuple | None = None

    def _hessian_type(self, H: np.ndarray) -> str:
        """The settings' Hessian type, unless H is not diagonal (then ``Dense``)."""
        if self.settings.hessian_type == "Diagonal" and \
                np.count_nonzero(H) != np.count_nonzero(np.diagonal(H)):
            return "Dense"
        return self.settings.hessian_type

    def solve(self, qp: TauQP) -> RawResult:
        """Solve a built tau-QP from a cold start.

        Returns:
            The raw result; the caller certifies it.

        Raises:
            SolverError: ProxSuite raised (chained).
        """
        why = check_data(qp)
        if why:
            return RawResult("error", None, 0, 0.0, why)
        n, n_eq, n_in = qp.H.shape[0], qp.A.shape[0], qp.C.shape[0]
        A = qp.A if n_eq else None
        b = qp.b if n_eq else None
        lower = np.full(n_in, -np.inf)
        dims = (n, n_eq, n_in, self._hessian_type(qp.H))
        t0 = time.perf_counter()
        try:
            if self._dims != dims:
                dense = proxsuite.proxqp.dense
                self._qp = dense.QP(n, n_eq, n_in, True,
                                    hessian_type=getattr(dense.HessianType, dims[3]),
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
                self._qp.init(H=qp.H, g=qp.g, A=A, b=b, C=qp.C, l=lower, u=qp.u,
                              l_box=qp.l_box, u_box=qp.u_box)
                self._dims = dims
            else:
                self._qp.update(H=qp.H, g=qp.g, A=A, b=b, C=qp.C, l=lower, u=qp.u,
                                l_box=qp.l_box, u_box=qp.u_box)
            self._qp.solve()
        except (RuntimeError, ValueError, TypeError) as e:
            self._dims = None
            raise SolverError(f"ProxSuite failed: {e}") from e
        elapsed = time.perf_counter() - t0
        info = self._qp.results.info
        out = proxsuite.proxqp.QPSolverOutput
        status = {out.PROXQP_SOLVED: "solved",
                  out.PROXQP_PRIMAL_INFEASIBLE: "infeasible"}.get(info.status, "error")
        return RawResult(status, np.array(self._qp.results.x), int(info.iter), elapsed,
                         str(info.status).rsplit(".", 1)[-1])
