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

The rounds are :class:`~grasp_torque_opt.methods.adaptive_rounds.Rounds`, on one
grasp's QP (:mod:`~grasp_torque_opt.methods.adaptive_qp`), with candidates from
:mod:`~grasp_torque_opt.methods.adaptive_candidate`; this module holds the public
names: :class:`Refiner` and :class:`AdaptiveSettings` (and :class:`Refined`, the
constants, for those who reach them here).
"""

from __future__ import annotations

from dataclasses import dataclass

from grasp_torque_opt.backends.daqp import DaqpSettings, DaqpWorkspace
from grasp_torque_opt.core.certificate import DEFAULT_TOLERANCE
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.tau_qp import TauQP
from grasp_torque_opt.methods.adaptive_rounds import Refined, Rounds


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
        rounds = Rounds(self, setup, maps, base, tolerance)
        rounds.deadline = deadline
        return rounds.run()
