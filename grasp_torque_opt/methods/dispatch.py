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
from dataclasses import dataclass
import time

from grasp_torque_opt.backends.base import Backend
from grasp_torque_opt.backends.registry import as_backend, available, make_solver
from grasp_torque_opt.core.bounds import make_bounds
from grasp_torque_opt.core.certificate import Certificate, certify, DEFAULT_TOLERANCE
from grasp_torque_opt.core.exceptions import InputError, SolverError
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.margin import cone_usage, planned_friction, torque_ratio
from grasp_torque_opt.core.scenario import Friction
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


def _ask(solver: Backend, qp: TauQP, deadline: float | None, cold: bool = False
         ) -> RawResult:
    """
    Call a backend's ``solve``, passing only what differs from the protocol's defaults.

    A subclass of a backend that narrowed ``solve`` (a test's fault injection) is still
    called as it can be when there is no deadline and no redo.
    """
    options = {} if deadline is None else {'deadline': deadline}
    if cold:
        options['cold'] = True
    return solver.solve(qp, **options)


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


@dataclass
class _Grasp:
    """What every method of one grasp shares: its maps and the planned problem's data."""

    setup: GraspSetup
    maps: GraspMaps
    friction: Friction  # the margin's reduced cone, or the scenario's own
    tau_min: np.ndarray
    tau_max: np.ndarray
    tolerance: float

    @property
    def args(self) -> tuple:
        """Return the arguments of every builder and reference method."""
        return (self.maps, self.friction, self.setup.external_wrench, self.tau_min,
                self.tau_max, self.setup.weights)

    def certify(self, tau: np.ndarray | None, f: np.ndarray | None) -> Certificate | None:
        """Certify (tau, f) against the exact problem; None without an answer."""
        return None if f is None else certify(self.maps.G, self.maps.J,
                                              self.setup.external_wrench, self.friction,
                                              self.tau_min, self.tau_max, tau, f,
                                              self.tolerance)


@dataclass
class _Answer:
    """
    A method's answer as it goes through the steps: who answered, what, and its certificate.

    ``qp``, ``solver``, ``fallback`` and ``first`` (the first backend's deadline) are the
    tau-QP's; None for a reference method.
    """

    raw: RawResult
    tau: np.ndarray | None
    f: np.ndarray | None
    used: str
    qp: TauQP | None = None
    solver: Backend | None = None
    fallback: Backend | None = None
    first: float | None = None
    cert: Certificate | None = None

    @property
    def certified(self) -> bool:
        """Whether the solver says solved and the certificate holds."""
        return self.raw.status == 'solved' and self.cert is not None and self.cert.ok


def solve(setup: GraspSetup, method: str = 'tau-qp', *, maps: GraspMaps | None = None,
          solver: Backend | None = None, backend: str = 'proxsuite',
          fallback: Backend | None = None,
          tolerance: float = DEFAULT_TOLERANCE, refiner: Refiner | None = None,
          deadline: float | None = None) -> Solution:
    """
    Solve one grasp with one method and certify the result.

    The steps: the grasp's maps (:func:`_grasp`); the first answer (:func:`_tau_qp`,
    with the min-max stage, or :func:`_reference`); its certificate, a warm answer
    that fails it redone cold (:func:`_redo_cold`); the fallback backend
    (:func:`_fallback`); the status (:func:`_decide`).

    Args:
        setup: the grasp.
        method: one of :data:`METHODS`.
        maps: G and J if already computed (else computed here).
        solver: a tau-QP solver to reuse across calls (tau-qp; for
            tau-qp-adaptive, the paper's N-gon it falls back to): a backend of
            :mod:`grasp_torque_opt.backends`, or a solver of the caller's own
            (``solve(qp) -> RawResult``; it gets no deadline and no cold redo).
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
    _check_method(setup, method)
    if method == 'tau-qp-adaptive':
        # The adaptive refinement plans in the margin's reduced cone; the usage and the
        # ratio are then measured as for tau-qp.
        planned = dataclasses.replace(setup, friction=planned_friction(setup.friction))
        return planner_metrics(_solve_adaptive(planned, maps, solver, backend, fallback,
                                               tolerance, refiner, deadline), setup)
    timings = {}
    t0 = time.perf_counter()
    grasp = _grasp(setup, maps, tolerance)
    t1 = time.perf_counter()
    timings['maps'] = t1 - t0
    if method == 'tau-qp':
        answer, t2 = _tau_qp(grasp, solver, backend, fallback, deadline)
    else:
        t2 = time.perf_counter()
        answer = _reference(grasp, method)
    t3 = time.perf_counter()
    timings['build'] = t2 - t1
    timings['solve'] = t3 - t2
    answer.cert = grasp.certify(answer.tau, answer.f)
    if method == 'tau-qp':
        _redo_cold(grasp, answer)
    timings['certify'] = time.perf_counter() - t3
    if method == 'tau-qp' and answer.fallback is not None and not answer.certified:
        t4 = time.perf_counter()
        _fallback(grasp, answer, deadline)
        timings['fallback'] = time.perf_counter() - t4
    return _decide(grasp, method, answer, timings, deadline)


def _check_method(setup: GraspSetup, method: str) -> None:
    """
    Refuse an unknown method, and min-max with a method other than tau-qp.

    Raises:
        ValueError: an unknown method, naming the known ones.
        InputError: ``objective.type`` min-max with another method.
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    if setup.objective == 'min-max' and method != 'tau-qp':
        raise InputError('objective.type', f'min-max is solved by the tau-qp method only, '
                         f'not {method}')


def _grasp(setup: GraspSetup, maps: GraspMaps | None, tolerance: float) -> _Grasp:
    """Return the grasp's maps (computed unless given) and its planned data."""
    if maps is None:
        maps = setup.maps()
    tau_min, tau_max = setup.tau_bounds
    # The margin's reduced cone, or the friction itself.
    return _Grasp(setup, maps, planned_friction(setup.friction), tau_min, tau_max, tolerance)


def _tau_qp(grasp: _Grasp, solver: Backend | None, backend: str, fallback: Backend | None,
            deadline: float | None) -> tuple[_Answer, float]:
    """
    Build the tau-QP (after the min-max LP for that objective) and ask the first backend.

    The first backend gets :data:`PRIMARY_SHARE` of the time left. A first backend that
    raises is an error answer when there is a fallback to ask.

    Returns:
        The answer, and the ``time.perf_counter()`` value when the build ended [s].

    Raises:
        SolverError: the first backend raised and there is no fallback.
    """
    setup = grasp.setup
    qp = build_tau_qp(*grasp.args)
    stage = None
    if setup.objective == 'min-max':
        # The LP's t*, then the sum of squares within |tau + offset| <= t* limit / w.
        t_lp = time.perf_counter()  # the LP first, with the QP's share of the time
        stage = minmax_stage(qp, setup.hand.torque_limits, setup.weights,
                             setup.torque_offset, _share(t_lp, deadline))
        qp = stage.qp
    t2 = time.perf_counter()
    solver = as_backend(solver if solver is not None else make_solver(backend), backend)
    answer = _Answer(RawResult('error', None, 0, 0.0, ''), None, None, solver.name, qp, solver)
    if stage is not None and stage.status not in ('optimal', 'infeasible'):
        answer.raw = RawResult('error', None, 0, 0.0, stage.message)  # no min-max optimum
        return answer, t2
    if stage is not None and fallback is None and solver.name != 'daqp' and \
            available('daqp'):
        # The tightened box leaves a thin feasible set: ProxSuite called 5 of 60
        # such QPs on random Allegro grasps PRIMAL_INFEASIBLE, DAQP solved all.
        fallback = make_solver('daqp')
    answer.fallback = None if fallback is None else as_backend(fallback, 'fallback')
    answer.first = _share(t2, deadline)
    try:
        raw = _ask(solver, qp, answer.first)
    except SolverError as e:
        if fallback is None:
            raise
        raw = RawResult('error', None, 0, 0.0, str(e))
    if stage is not None:
        raw = dataclasses.replace(raw, message=f'{stage.message}; {raw.message}')
    answer.raw, answer.tau, answer.f = qp_answer(qp, raw)
    return answer, t2


def _share(start: float, deadline: float | None) -> float | None:
    """Return the first backend's deadline: :data:`PRIMARY_SHARE` of the time left [s]."""
    return None if deadline is None else start + PRIMARY_SHARE * max(0.0, deadline - start)


def _reference(grasp: _Grasp, method: str) -> _Answer:
    """Solve with a reference method (f in its x)."""
    # The reference methods' solvers (Clarabel, SciPy's SLSQP) are imported where
    # they are used: the node runs the tau-QP without them.
    if method == 'force-qp':
        from grasp_torque_opt.reference.force_qp import solve_force_qp
        raw = solve_force_qp(*grasp.args, objective='force')
    elif method == 'socp':
        from grasp_torque_opt.reference.exact_socp import solve_exact_socp
        raw = solve_exact_socp(*grasp.args)
    else:
        from grasp_torque_opt.reference.exact_nlp import solve_exact_nlp
        raw = solve_exact_nlp(*grasp.args)
    J = grasp.maps.J
    f = None if raw.x is None else raw.x[:J.shape[0]]
    return _Answer(raw, None if f is None else J.T @ f, f, method)


def _redo_cold(grasp: _Grasp, answer: _Answer) -> None:
    """Redo cold, in the same call, a warm answer that lands off the certificate."""
    if answer.solver.last_warm and answer.raw.status == 'solved' and \
            answer.cert is not None and not answer.cert.ok:
        answer.raw, answer.tau, answer.f = qp_answer(
            answer.qp, _ask(answer.solver, answer.qp, answer.first, cold=True))
        answer.cert = grasp.certify(answer.tau, answer.f)


def _fallback(grasp: _Grasp, answer: _Answer, deadline: float | None) -> None:
    """Ask the fallback backend, with the rest of the time; keep its answer if certified."""
    raw, tau, f = qp_answer(answer.qp, _ask(answer.fallback, answer.qp, deadline))
    if raw.status == 'solved' and f is not None:
        cert = grasp.certify(tau, f)
        if cert.ok:
            answer.used = answer.fallback.name
            # One line a user can act on: what went wrong first, what answered instead,
            # and that the answer is as trustworthy as any (it passed the certificate).
            answer.raw = dataclasses.replace(raw, message=(
                f'fallback after {answer.raw.message}: {answer.fallback.name} solved the same '
                f'tau-QP instead ({raw.message}); its answer is certified against the exact '
                'cone like any other'))
            answer.tau, answer.f, answer.cert = tau, f, cert


def _decide(grasp: _Grasp, method: str, answer: _Answer, timings: dict,
            deadline: float | None) -> Solution:
    """
    Decide the status: optimal if certified; infeasible only if confirmed; else failed.

    A polygon method's infeasible verdict needs the independent LP to agree (skipped
    once the deadline has passed); the SOCP's is its solver's.
    """
    setup, raw, cert = grasp.setup, answer.raw, answer.cert
    out = Solution(status=FAILED, method=method, joints=list(setup.hand.joints),
                   iterations=raw.iterations, solve_time_s=raw.solve_time_s,
                   certificate=cert, timings=timings, backend=answer.used,
                   objective=setup.objective, friction_margin=setup.friction.margin)
    if answer.certified:
        out.status, out.tau, out.wrenches = OPTIMAL, answer.tau, answer.f.reshape(-1, 4)
        out.message = f'certified (solver: {raw.message})'
        return planner_metrics(out, setup)
    why = (f'solver: {raw.message}' if cert is None or cert.ok or raw.status != 'solved'
           else f'solver: {raw.message}, certificate failed (worst residual {cert.worst:.3g})')
    if method in LINEARIZED and deadline is not None and time.perf_counter() >= deadline:
        out.message = f'not certified, LP skipped: time budget spent ({why})'
    elif method in LINEARIZED:
        feasible = linearized_feasible(grasp.maps, grasp.friction, setup.external_wrench,
                                       grasp.tau_min, grasp.tau_max)
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
