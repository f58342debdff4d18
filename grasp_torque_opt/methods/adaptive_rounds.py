# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
One grasp's rounds of ``tau-qp-adaptive`` and what they found (:class:`Refined`).

docs/adaptive.md has the algorithm, :mod:`~grasp_torque_opt.methods.adaptive` its
overview: round 0 on the circumscribed polygon, then per round a step with the
cone's curvature, a candidate restored onto the exact cone
(:mod:`~grasp_torque_opt.methods.adaptive_candidate`) and, while the gap is open,
the relaxation at the candidate's directions. The QPs and the rows they share are
:class:`~grasp_torque_opt.methods.adaptive_qp.GraspQP`'s.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import TYPE_CHECKING

from grasp_torque_opt.core.certificate import Certificate
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.tau_qp import TauQP
from grasp_torque_opt.methods.adaptive_candidate import candidate, kkt_bound, restore
from grasp_torque_opt.methods.adaptive_qp import GraspQP
import numpy as np

if TYPE_CHECKING:
    from grasp_torque_opt.methods.adaptive import Refiner

#: Round 0's polygon when refining: its directions are then close enough that one
#: round closes the gap for most grasps (bench/adaptive.py: 169 of 200 with 16
#: sides, fewer with 8; 24 or 32 sides cost as much in larger QPs as they save).
FIRST_SIDES = 16


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


class Rounds(GraspQP):
    """
    One grasp's rounds, on its QP; the refiner keeps the warm start between grasps.

    Args:
        refiner: its settings, workspace and warm-start state.
        setup: the grasp.
        maps: its G and J.
        base: its tau-QP, whose decomposition every round reuses.
        tolerance: the certificate's tolerance, SI units.
    """

    def __init__(self, refiner: Refiner, setup: GraspSetup, maps: GraspMaps, base: TauQP,
                 tolerance: float) -> None:
        self.refiner, self.s = refiner, refiner.settings
        sides = self.s.first_sides
        if sides is None:
            fr = setup.friction
            sides = fr.sides if self.s.max_rounds == 0 else max(FIRST_SIDES, fr.sides)
        super().__init__(refiner.workspace, setup, maps, base, tolerance, sides)

    def run(self) -> Refined:
        """Run the grasp warm from the refiner's last answer if it fits, else cold."""
        s = self.s
        last = self.refiner.last
        if s.warm_start and last is not None and last[0] == self.key():
            self.refiner.warm_solves += 1
            self.load(warm=True)
            out = self._rounds(-math.inf, None, 'refined', (None,) + last[1:4], last[4], 1)
            if out.tau is not None:
                return out
            self.refiner.warm_fallbacks += 1
            self.reset_slots()
        self.load(warm=False)
        raw, x, lam, y = self.qp()
        if x is None:
            return self._done(None, -math.inf, 0, 'circumscribed', f'round 0: {raw.message}',
                              raw.status == 'infeasible')
        point = self.point(x)
        best = candidate(self, x, point)
        lower = -math.inf
        # Round 0's bound is only needed if nothing better comes (rows change below).
        first = (self.rows.copy(), lam.copy(), y.copy())
        if best is not None or s.max_rounds == 0:
            lower = self.bound(lam, y)
        out = self._rounds(lower, best, 'circumscribed' if best is not None else 'refined',
                           point, np.maximum(lam[:, :-1], 0.0).sum(axis=1), 0, first)
        return out

    def _rounds(self, lower: float, best, source: str, point, nu: np.ndarray, start: int,
                first=None) -> Refined:
        """
        Run the refinement rounds from a point's directions and multipliers nu.

        Args:
            lower: the best checked lower bound on tau^T W tau so far (-inf: none).
            best: the best certified candidate so far, as
                :func:`~grasp_torque_opt.methods.adaptive_candidate.candidate` returns
                it, or None.
            source: what ``best`` came from (``refined`` or ``circumscribed``).
            point: the point whose directions the first step starts at, as
                :meth:`~grasp_torque_opt.methods.adaptive_qp.GraspQP.point` returns it
                (its f is not used: None for a warm start).
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
            self.turn(u, ok)
            raw, xs, lam_s, y_s = self.qp(*self.curvature(u, nt, ok, nu))
            if xs is None:
                message = f'round {rounds} step: {raw.message}'
                break
            last_nu = np.maximum(lam_s[:, :-1], 0.0).sum(axis=1)
            xh, point, duals = restore(self, xs, lam_s, self.ws.multipliers[:self.n])
            if not np.all(np.isfinite(xh)):
                xh, point, duals = xs, self.point(xs), None
            cand = candidate(self, xh, point)
            if cand is not None and (best is None or cand[0] < best[0]):
                best, source = cand, 'refined'
                self.refiner.last = (self.key(), point[1], point[2], point[3], last_nu)
            if best is not None:  # without a candidate no bound closes the gap
                lower = max(lower, kkt_bound(self, duals))
                if gap() <= s.gap_tolerance:
                    message = 'gap within tolerance'
                    break
            # The restored point's own multipliers bound loosely while it is still a
            # step away (10 to 100 times its excess, measured): the relaxation with
            # the facets at its directions, solved warm, has exact multipliers.
            self.turn(point[1], point[3])
            raw, xl, lam_l, y_l = self.qp(base.H, base.g)
            if xl is None:
                message = f'round {rounds} relaxation: {raw.message}'
                break
            lower = max(lower, self.bound(lam_l, y_l))
            nu = np.maximum(lam_l[:, :-1], 0.0).sum(axis=1)
        else:
            if gap() <= s.gap_tolerance:
                message = 'gap within tolerance'
        if lower == -math.inf and first is not None:
            self.rows = first[0]
            lower = self.bound(first[1], first[2])
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
