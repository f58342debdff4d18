"""One entry point for every method: kinematics, build, solve, certify, decide.

The status of a :class:`Solution` is decided here, never by a solver alone:
``optimal`` needs the certificate; ``infeasible`` from a polygon method needs
the independent LP of :mod:`grasp_torque_opt.reference.feasibility` to agree.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from grasp_torque_opt.backends import make_solver
from grasp_torque_opt.backends.proxsuite import TauQPSolver
from grasp_torque_opt.core.certificate import DEFAULT_TOLERANCE, Certificate, certify
from grasp_torque_opt.core.exceptions import SolverError
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.solution import (
    FAILED,
    INFEASIBLE,
    OPTIMAL,
    RawResult,
    Solution,
)
from grasp_torque_opt.core.tau_qp import TauQP, build_tau_qp
from grasp_torque_opt.reference.feasibility import linearized_feasible

#: Methods: the product's (``tau-qp``) and the references.
METHODS = ("tau-qp", "force-qp", "socp", "nlp")
#: Methods whose feasible set is the linearized (polygon) one.
LINEARIZED = ("tau-qp", "force-qp")


def qp_answer(qp: TauQP, raw: RawResult
              ) -> tuple[RawResult, np.ndarray | None, np.ndarray | None]:
    """(raw, tau, f) of a tau-QP solver's answer; (raw, None, None) without one.

    An x of the wrong shape is no answer: ``raw`` comes back as an error saying so
    (the next backend may still answer), never as an exception in the cycle.
    """
    n = qp.H.shape[0]
    if raw.x is not None and np.shape(raw.x) != (n,):
        raw = dataclasses.replace(raw, status="error", x=None, message=(
            f"{raw.message}, but x has shape {np.shape(raw.x)} for {n} variables"))
    if raw.x is None:
        return raw, None, None
    return raw, qp.split(raw.x)[0], qp.wrenches(raw.x)


def solve(setup: GraspSetup, method: str = "tau-qp", *, maps: GraspMaps | None = None,
          solver: TauQPSolver | None = None, backend: str = "proxsuite",
          fallback: TauQPSolver | None = None,
          tolerance: float = DEFAULT_TOLERANCE) -> Solution:
    """Solve one grasp with one method and certify the result.

    Args:
        setup: the grasp.
        method: one of :data:`METHODS`.
        maps: G and J if already computed (else computed here).
        solver: a tau-QP solver to reuse across calls (tau-qp only), any backend
            of :mod:`grasp_torque_opt.backends`.
        backend: the backend to use when no solver is given (tau-qp only).
        fallback: a second tau-QP solver, asked only when the first gives nothing
            certifiable (ProxSuite called some holdable Allegro loads
            PRIMAL_INFEASIBLE or hit its cap; DAQP solved them). Its answer is
            certified the same way; ``Solution.backend`` says who solved.
        tolerance: certificate tolerance, SI units.

    Returns:
        A solution whose status is ``optimal`` only if certified.
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    timings = {}
    t0 = time.perf_counter()
    if maps is None:
        maps = setup.maps()
    t1 = time.perf_counter()
    timings["maps"] = t1 - t0
    tau_min, tau_max = setup.tau_bounds
    args = (maps, setup.friction, setup.external_wrench, tau_min, tau_max, setup.weights)
    J = maps.J
    used = method
    if method == "tau-qp":
        qp = build_tau_qp(*args)
        t2 = time.perf_counter()
        solver = solver or make_solver(backend)
        used = getattr(solver, "name", backend)
        try:
            raw = solver.solve(qp)
        except SolverError as e:
            if fallback is None:
                raise
            raw = RawResult("error", None, 0, 0.0, str(e))
        raw, tau, f = qp_answer(qp, raw)
    else:
        t2 = time.perf_counter()
        # The reference methods' solvers (Clarabel, SciPy's SLSQP) are imported where
        # they are used: the node runs the tau-QP without them.
        if method == "force-qp":
            from grasp_torque_opt.reference.force_qp import solve_force_qp
            raw = solve_force_qp(*args, objective="force")
        elif method == "socp":
            from grasp_torque_opt.reference.exact_socp import solve_exact_socp
            raw = solve_exact_socp(*args)
        else:
            from grasp_torque_opt.reference.exact_nlp import solve_exact_nlp
            raw = solve_exact_nlp(*args)
        f = None if raw.x is None else raw.x[:J.shape[0]]
        tau = None if f is None else J.T @ f
    t3 = time.perf_counter()
    timings["build"] = t2 - t1
    timings["solve"] = t3 - t2

    def certified(tau, f) -> Certificate | None:
        return None if f is None else certify(maps.G, J, setup.external_wrench,
                                               setup.friction, tau_min, tau_max, tau, f,
                                               tolerance)

    cert = certified(tau, f)
    if method == "tau-qp" and getattr(solver, "last_warm", False) and \
            raw.status == "solved" and cert is not None and not cert.ok:
        # A warm start that lands off the certificate is redone cold in the same call.
        raw, tau, f = qp_answer(qp, solver.solve(qp, cold=True))
        cert = certified(tau, f)
    timings["certify"] = time.perf_counter() - t3
    if method == "tau-qp" and fallback is not None and \
            not (raw.status == "solved" and cert is not None and cert.ok):
        t4 = time.perf_counter()
        raw2, tau2, f2 = qp_answer(qp, fallback.solve(qp))
        if raw2.status == "solved" and f2 is not None:
            cert2 = certified(tau2, f2)
            if cert2.ok:
                used = getattr(fallback, "name", "fallback")
                raw = dataclasses.replace(raw2, message=f"{raw2.message}; fallback after "
                                          f"{raw.message}")
                tau, f, cert = tau2, f2, cert2
        timings["fallback"] = time.perf_counter() - t4

    out = Solution(status=FAILED, method=method, joints=list(setup.hand.joints),
                   iterations=raw.iterations, solve_time_s=raw.solve_time_s,
                   certificate=cert, timings=timings, backend=used)
    if raw.status == "solved" and cert is not None and cert.ok:
        out.status, out.tau, out.wrenches = OPTIMAL, tau, f.reshape(-1, 4)
        out.message = f"certified (solver: {raw.message})"
        return out
    why = (f"solver: {raw.message}" if cert is None or cert.ok or raw.status != "solved"
           else f"solver: {raw.message}, certificate failed (worst residual {cert.worst:.3g})")
    if method in LINEARIZED:
        feasible = linearized_feasible(maps, setup.friction, setup.external_wrench,
                                       tau_min, tau_max)
        if feasible is False:
            out.status, out.message = INFEASIBLE, f"infeasible, confirmed by LP ({why})"
        elif feasible:
            out.message = f"not certified although an LP finds the load holdable ({why})"
        else:
            out.message = f"not certified, LP undecided ({why})"
    elif method == "socp" and raw.status == "infeasible":
        out.status, out.message = INFEASIBLE, f"infeasible ({why})"
    else:
        out.message = f"not certified ({why})"
    return out
