# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
One entry point for every method: kinematics, build, solve, certify, decide.

The status of a :class:`Solution` is decided here, never by a solver alone:
``optimal`` needs the certificate; ``infeasible`` from a polygon method needs
the independent LP of :mod:`grasp_torque_opt.reference.feasibility` to agree
(for ``tau-qp-adaptive``, the LP on the circumscribed polygon: no torque holds
the load even with the exact cone).
"""

from __future__ import annotations

import dataclasses
import inspect
import time

from grasp_torque_opt.backends import available, make_solver
from grasp_torque_opt.backends.proxsuite import TauQPSolver
from grasp_torque_opt.core.bounds import make_bounds
from grasp_torque_opt.core.certificate import Certificate, certify, DEFAULT_TOLERANCE
from grasp_torque_opt.core.exceptions import InputError, SolverError
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.margin import cone_usage, planned_friction, torque_ratio
from grasp_torque_opt.core.solution import (
    FAILED,
    INFEASIBLE,
    OPTIMAL,
    RawResult,
    Solution,
)
from grasp_torque_opt.core.tau_qp import build_tau_qp, TauQP
from grasp_torque_opt.methods.adaptive import AdaptiveSettings, Refiner
from grasp_torque_opt.methods.minmax import minmax_stage
from grasp_torque_opt.reference.feasibility import linearized_feasible
import numpy as np

#: Methods: the product's (``tau-qp``; ``tau-qp-adaptive``, its refinement to the
#: exact cone with certified bounds, docs/adaptive.md) and the references.
METHODS = ('tau-qp', 'tau-qp-adaptive', 'force-qp', 'socp', 'nlp')
#: Methods whose feasible set is the linearized (polygon) one.
LINEARIZED = ('tau-qp', 'force-qp')
#: Under a deadline, the share of the time left that the first backend may use; the
#: fallback gets the rest (DAQP answered the Allegro's QPs in under 1 ms here).
PRIMARY_SHARE = 0.8


_TAKES_DEADLINE: dict[type, bool] = {}


def _timed(solver, qp: TauQP, deadline: float | None, **kwargs) -> RawResult:
    """
    Call ``solver.solve(qp)``, passing the deadline when there is one and the solver takes it.

    Every backend takes it; a solver of the caller's own that does not runs on its
    iteration caps alone.
    """
    if deadline is not None:
        takes = _TAKES_DEADLINE.get(type(solver))
        if takes is None:
            params = inspect.signature(solver.solve).parameters
            takes = _TAKES_DEADLINE[type(solver)] = 'deadline' in params or any(
                p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values())
        if takes:
            kwargs['deadline'] = deadline
    return solver.solve(qp, **kwargs)


def qp_answer(qp: TauQP, raw: RawResult
              ) -> tuple[RawResult, np.ndarray | None, np.ndarray | None]:
    """
    (raw, tau, f) of a tau-QP solver's answer; (raw, None, None) without one.

    An x of the wrong shape is no answer: ``raw`` comes back as an error saying so
    (the next backend may still answer), never as an exception in the cycle.
    """
    n = qp.H.shape[0]
    if raw.x is not None and np.shape(raw.x) != (n,):
        raw = dataclasses.replace(raw, status='error', x=None, message=(
            f'{raw.message}, but x has shape {np.shape(raw.x)} for {n} variables'))
    if raw.x is None:
        return raw, None, None
    return raw, qp.split(raw.x)[0], qp.wrenches(raw.x)


def planner_metrics(out: Solution, setup: GraspSetup) -> Solution:
    """
    Fill the planner's numbers of a solution (docs/planner.md).

    They are the objective and the margin planned with, and for an optimum the friction
    usage on the *unreduced* cone and max |tau + offset| / limit.
    """
    out.objective, out.friction_margin = setup.objective, setup.friction.margin
    if out.optimal:
        out.friction_usage = cone_usage(out.wrenches, setup.friction.mu1, setup.friction.mu2)
        out.max_torque_ratio = torque_ratio(out.tau, setup.hand.torque_limits,
                                            setup.torque_offset)
    return out


def solve(setup: GraspSetup, method: str = 'tau-qp', *, maps: GraspMaps | None = None,
          solver: TauQPSolver | None = None, backend: str = 'proxsuite',
          fallback: TauQPSolver | None = None,
          tolerance: float = DEFAULT_TOLERANCE, refiner: Refiner | None = None,
          deadline: float | None = None) -> Solution:
    """
    Solve one grasp with one method and certify the result.

    Args:
        setup: the grasp.
        method: one of :data:`METHODS`.
        maps: G and J if already computed (else computed here).
        solver: a tau-QP solver to reuse across calls (tau-qp; for
            tau-qp-adaptive, the paper's N-gon it falls back to), any backend
            of :mod:`grasp_torque_opt.backends`.
        backend: the backend to use when no solver is given (as ``solver``).
        fallback: a second tau-QP solver, asked only when the first gives nothing
            certifiable (ProxSuite called some holdable Allegro loads
            PRIMAL_INFEASIBLE or hit its cap; DAQP solved them). Its answer is
            certified the same way; ``Solution.backend`` says who solved.
        tolerance: certificate tolerance, SI units.
        refiner: tau-qp-adaptive's rounds (its settings: gap tolerance, rounds),
            reusable across calls; default :class:`Refiner` ().
        deadline: ``time.perf_counter()`` value by which the tau-QP's solvers must
            stop [s] (the node's cycle budget; None: only their iteration caps).
            The first solver may use :data:`PRIMARY_SHARE` of the time left, the
            fallback the rest; past it, the independent LP that tells an
            infeasible load from a failed solve is skipped (status ``failed``,
            "LP skipped").

    The setup's friction margin k plans and certifies inside the cone of
    mu/(1+k) (:func:`~grasp_torque_opt.core.margin.planned_friction`); its
    ``objective`` ``min-max`` first solves the min-max LP
    (:mod:`grasp_torque_opt.methods.minmax`, tau-qp only).

    Returns:
        A solution whose status is ``optimal`` only if certified.
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    if setup.objective == 'min-max' and method != 'tau-qp':
        raise InputError('objective.type', f'min-max is solved by the tau-qp method only, '
                         f'not {method}')
    if method == 'tau-qp-adaptive':
        # The adaptive refinement plans in the margin's reduced cone; the usage and the
        # ratio are then measured as for tau-qp.
        planned = dataclasses.replace(setup, friction=planned_friction(setup.friction))
        return planner_metrics(_solve_adaptive(planned, maps, solver, backend, fallback,
                                               tolerance, refiner, deadline), setup)
    timings = {}
    t0 = time.perf_counter()
    if maps is None:
        maps = setup.maps()
    t1 = time.perf_counter()
    timings['maps'] = t1 - t0
    tau_min, tau_max = setup.tau_bounds
    friction = planned_friction(setup.friction)  # the margin's reduced cone, or itself
    args = (maps, friction, setup.external_wrench, tau_min, tau_max, setup.weights)
    J = maps.J
    used = method
    if method == 'tau-qp':
        qp = build_tau_qp(*args)
        stage = None
        if setup.objective == 'min-max':
            # The LP's t*, then the sum of squares within |tau + offset| <= t* limit / w.
            t_lp = time.perf_counter()  # the LP first, with the QP's share of the time
            stage = minmax_stage(qp, setup.hand.torque_limits, setup.weights,
                                 setup.torque_offset, None if deadline is None else
                                 t_lp + PRIMARY_SHARE * max(0.0, deadline - t_lp))
            qp = stage.qp
        t2 = time.perf_counter()
        solver = solver or make_solver(backend)
        used = getattr(solver, 'name', backend)
        if stage is not None and stage.status not in ('optimal', 'infeasible'):
            raw = RawResult('error', None, 0, 0.0, stage.message)  # no min-max optimum: none
            fallback = None
        else:
            if stage is not None and fallback is None and used != 'daqp' and \
                    available('daqp'):
                # The tightened box leaves a thin feasible set: ProxSuite called 5 of 60
                # such QPs on random Allegro grasps PRIMAL_INFEASIBLE, DAQP solved all.
                fallback = make_solver('daqp')
            first = None if deadline is None else \
                t2 + PRIMARY_SHARE * max(0.0, deadline - t2)
            try:
                raw = _timed(solver, qp, first)
            except SolverError as e:
                if fallback is None:
                    raise
                raw = RawResult('error', None, 0, 0.0, str(e))
            if stage is not None:
                raw = dataclasses.replace(raw, message=f'{stage.message}; {raw.message}')
        raw, tau, f = qp_answer(qp, raw)
    else:
        t2 = time.perf_counter()
        # The reference methods' solvers (Clarabel, SciPy's SLSQP) are imported where
        # they are used: the node runs the tau-QP without them.
        if method == 'force-qp':
            from grasp_torque_opt.reference.force_qp import solve_force_qp
            raw = solve_force_qp(*args, objective='force')
        elif method == 'socp':
            from grasp_torque_opt.reference.exact_socp import solve_exact_socp
            raw = solve_exact_socp(*args)
        else:
            from grasp_torque_opt.reference.exact_nlp import solve_exact_nlp
            raw = solve_exact_nlp(*args)
        f = None if raw.x is None else raw.x[:J.shape[0]]
        tau = None if f is None else J.T @ f
    t3 = time.perf_counter()
    timings['build'] = t2 - t1
    timings['solve'] = t3 - t2

    def certified(tau, f) -> Certificate | None:
        return None if f is None else certify(maps.G, J, setup.external_wrench,
                                              friction, tau_min, tau_max, tau, f,
                                              tolerance)

    cert = certified(tau, f)
    if method == 'tau-qp' and getattr(solver, 'last_warm', False) and \
            raw.status == 'solved' and cert is not None and not cert.ok:
        # A warm start that lands off the certificate is redone cold in the same call.
        raw, tau, f = qp_answer(qp, _timed(solver, qp, first, cold=True))
        cert = certified(tau, f)
    timings['certify'] = time.perf_counter() - t3
    if method == 'tau-qp' and fallback is not None and \
            not (raw.status == 'solved' and cert is not None and cert.ok):
        t4 = time.perf_counter()
        raw2, tau2, f2 = qp_answer(qp, _timed(fallback, qp, deadline))
        if raw2.status == 'solved' and f2 is not None:
            cert2 = certified(tau2, f2)
            if cert2.ok:
                used = getattr(fallback, 'name', 'fallback')
                raw = dataclasses.replace(raw2, message=f'{raw2.message}; fallback after '
                                          f'{raw.message}')
                tau, f, cert = tau2, f2, cert2
        timings['fallback'] = time.perf_counter() - t4

    out = Solution(status=FAILED, method=method, joints=list(setup.hand.joints),
                   iterations=raw.iterations, solve_time_s=raw.solve_time_s,
                   certificate=cert, timings=timings, backend=used,
                   objective=setup.objective, friction_margin=setup.friction.margin)
    if raw.status == 'solved' and cert is not None and cert.ok:
        out.status, out.tau, out.wrenches = OPTIMAL, tau, f.reshape(-1, 4)
        out.message = f'certified (solver: {raw.message})'
        return planner_metrics(out, setup)
    why = (f'solver: {raw.message}' if cert is None or cert.ok or raw.status != 'solved'
           else f'solver: {raw.message}, certificate failed (worst residual {cert.worst:.3g})')
    if method in LINEARIZED and deadline is not None and time.perf_counter() >= deadline:
        out.message = f'not certified, LP skipped: time budget spent ({why})'
    elif method in LINEARIZED:
        feasible = linearized_feasible(maps, friction, setup.external_wrench,
                                       tau_min, tau_max)
        if feasible is False:
            out.status, out.message = INFEASIBLE, f'infeasible, confirmed by LP ({why})'
        elif feasible:
            out.message = f'not certified although an LP finds the load holdable ({why})'
        else:
            out.message = f'not certified, LP undecided ({why})'
    elif method == 'socp' and raw.status == 'infeasible':
        out.status, out.message = INFEASIBLE, f'infeasible ({why})'
    else:
        out.message = f'not certified ({why})'
    return out


def _solve_adaptive(setup: GraspSetup, maps: GraspMaps | None, solver, backend: str,
                    fallback, tolerance: float, refiner: Refiner | None,
                    deadline: float | None = None) -> Solution:
    """
    Solve with tau-qp-adaptive: the rounds of :mod:`~grasp_torque_opt.methods.adaptive`.

    The answer has its certified bounds attached. It is the paper's N-gon's (the tau-qp
    path) when no round gave a candidate (or DAQP, which the rounds need, is not
    installed). Under a deadline the rounds get :data:`PRIMARY_SHARE` of the time left and
    the polygon the rest.
    """
    t0 = time.perf_counter()
    if maps is None:
        maps = setup.maps()
    t1 = time.perf_counter()
    tau_min, tau_max = setup.tau_bounds
    qp = build_tau_qp(maps, setup.friction, setup.external_wrench, tau_min, tau_max,
                      setup.weights)
    t2 = time.perf_counter()
    if refiner is None and available('daqp'):
        refiner = Refiner()
    settings = AdaptiveSettings() if refiner is None else refiner.settings
    try:
        if refiner is None:
            ref, why = None, 'the rounds need DAQP, which is not installed (pip install daqp)'
        else:
            first = None if deadline is None else \
                t2 + PRIMARY_SHARE * max(0.0, deadline - t2)
            ref = refiner.refine(setup, maps, qp, tolerance, deadline=first)
            why = ref.message
    except SolverError as e:  # a failed round is answered by the polygon below
        ref, why = None, str(e)
    t3 = time.perf_counter()
    timings = {'maps': t1 - t0, 'build': t2 - t1, 'solve': t3 - t2}
    lower = -float('inf') if ref is None else ref.lower
    rounds, qps = (0, 0) if ref is None else (ref.rounds, ref.qp_solves)
    joints = list(setup.hand.joints)
    if ref is not None and ref.tau is not None:
        cert = ref.certificate  # certified in the rounds, with this tolerance
        bounds = make_bounds(lower, ref.upper, settings.gap_tolerance, rounds, qps, ref.source)
        gap = 'no lower bound' if bounds.gap is None else f'gap {100 * bounds.gap:.3g}%'
        return Solution(status=OPTIMAL, method='tau-qp-adaptive', joints=joints, tau=ref.tau,
                        wrenches=ref.f.reshape(-1, 4), iterations=ref.iterations,
                        solve_time_s=ref.solve_time_s, certificate=cert,
                        message=f'certified ({ref.source}, {rounds} rounds, {qps} QPs, {gap}: '
                                f'{why})', timings=timings, backend='daqp', bounds=bounds)
    # No certified candidate: the paper's N-gon answers (never nothing when it can).
    poly = solve(setup, 'tau-qp', maps=maps, solver=solver, backend=backend,
                 fallback=fallback, tolerance=tolerance, deadline=deadline)
    timings.update({f'polygon_{k}': v for k, v in poly.timings.items() if k != 'maps'})
    upper = None if poly.tau is None else float(poly.tau @ (setup.weights * poly.tau))
    out = dataclasses.replace(poly, method='tau-qp-adaptive', timings=timings,
                              bounds=make_bounds(lower, upper, settings.gap_tolerance, rounds,
                                                 qps, 'polygon'))
    if poly.optimal:
        out.message = f"{poly.message}; the paper's N-gon, as the rounds gave none ({why})"
    elif ref is not None and ref.outer_infeasible and \
            (deadline is None or time.perf_counter() < deadline) and linearized_feasible(
            maps, setup.friction, setup.external_wrench, tau_min, tau_max,
            circumscribed=True) is False:
        out.status = INFEASIBLE
        out.message = ('infeasible even for the circumscribed polygon, which contains the '
                       f'exact cone; confirmed by LP ({why})')
    else:
        out.status = FAILED
        out.message = f"not certified: the rounds ({why}) and the paper's N-gon ({poly.message})"
    return out
