# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The node's cycle compiled: maps, build, warm ProxSuite or DAQP solve and certificate in C++.

``grasp_torque_opt.native._fast_cycle`` (``src/fast_cycle.hpp``, built by ``setup.py`` with
pybind11, Eigen and ProxSuite's C++ headers; on x86-64 also ``_fast_cycle_avx2``, used
where the CPU runs AVX2 and FMA) is the Python cycle written again, rule for rule, for
the case the node runs on every joint state (docs/design.md section 2.6):

- the ``tau-qp`` method and the ``sum-of-squares`` objective;
- the ProxSuite backend with the package's settings (Diagonal Hessian,
  PrimalDualLDLT, the preconditioner of the first problem kept), or the DAQP backend
  (DAQP's C entry in the daqp module's extension, called as
  :class:`~grasp_torque_opt.backends.daqp.DaqpSolver` calls it: the same settings, the
  KKT check, a warm start from the last solved QP's active set);
- A = [G; J^T] of full column rank (the QR branch of
  :func:`~grasp_torque_opt.core.tau_qp.decompose`: no internal-force variables, as
  for the Allegro's four fingertips).

The contact links' placements and Jacobians are computed in the same call where the
hand is a tree of 1-DoF revolute and prismatic joints
(:class:`~grasp_torque_opt.core.tree_kinematics.TreeKinematics`'s rules, held to
Pinocchio's at the first configuration of each contact link), else asked of Pinocchio
in Python (about 15 us a cycle: two calls a contact into its binding). A warm answer
that the solver does not call solved, or that fails the KKT check or the certificate,
is redone cold in the same call, as the Python solver does. What the compiled cycle
cannot certify, it hands back: :meth:`CompiledCycle.solve` returns None with the
reason, and the controller runs the Python cycle, which stays the reference and is
what the tests hold the compiled one to.
"""

from __future__ import annotations

from dataclasses import dataclass

from grasp_torque_opt.backends import daqp as daqp_backend
from grasp_torque_opt.backends.proxsuite import (
    ESTIMATE_DECAY,
    INNER_ITERATION_S,
    KKT_TOLERANCE,
    ProxSuiteSettings,
    TauQPSolver,
)
from grasp_torque_opt.core.certificate import Certificate
from grasp_torque_opt.core.friction import contact_block
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.margin import planned_friction
from grasp_torque_opt.core.solution import OPTIMAL, Solution
from grasp_torque_opt.core.tau_qp import BOX_MARGIN, QR_RTOL
from grasp_torque_opt.core.tree_kinematics import TreeKinematics
from grasp_torque_opt.methods.batch import contact_arrays
from grasp_torque_opt.native.loader import fast_cycle, IMPORT_ERROR
import numpy as np
import pinocchio as pin

#: Share of the time left that the compiled solve (ProxSuite or DAQP) may use; the fallback gets
#: the rest (as :data:`grasp_torque_opt.methods.dispatch.PRIMARY_SHARE`).
PRIMARY_SHARE = 0.8
#: Outcome codes after which the solver was tried (warm, and cold if the warm answer
#: failed): the controller asks its fallback backend next, not the same solver again.
SOLVER_CODES = () if fast_cycle is None else (
    fast_cycle.NOT_SOLVED, fast_cycle.NOT_CERTIFIED, fast_cycle.TIMED_OUT)
#: After this many cycles in a row handed back as not of full column rank (a grasp
#: with internal-force variables), the compiled cycle is not tried again for the grasp.
RANK_GIVE_UP = 10


def available() -> bool:
    """Tell whether the compiled cycle was built and imports."""
    return fast_cycle is not None


def unsupported(setup: GraspSetup, method: str, solver) -> str:
    """
    Say why the compiled cycle does not take this grasp and solver ('' if it does).

    Only what is known before a cycle: a grasp whose A turns out rank-deficient at some
    configuration is handed back by :meth:`CompiledCycle.solve` instead.
    """
    if fast_cycle is None:
        return IMPORT_ERROR
    if setup.hand.velocity_map is not None:
        return 'coupled joints (the compiled cycle takes a column selection of J)'
    if setup.hand.base_link is not None:
        return 'hand.base_link (the compiled cycle writes the grasp in the root frame)'
    if method != 'tau-qp':
        return f'method {method} (the compiled cycle solves tau-qp)'
    if setup.objective != 'sum-of-squares':
        return f'objective {setup.objective} (the compiled cycle solves sum-of-squares)'
    if isinstance(solver, daqp_backend.DaqpSolver):
        if daqp_backend.daqp_entry() is None:
            return ("backend daqp (the compiled cycle calls DAQP's C entry of daqp "
                    f"{', '.join(daqp_backend.DAQP_C_VERSIONS)} only)")
        return ''
    if not isinstance(solver, TauQPSolver):
        return f"backend {getattr(solver, 'name', type(solver).__name__)} (the compiled " \
               'cycle solves with ProxSuite or DAQP)'
    s = solver.settings
    if (s.hessian_type, s.dense_backend, s.preconditioner) != \
            ('Diagonal', 'PrimalDualLDLT', 'first'):
        return 'ProxSuite settings other than Diagonal, PrimalDualLDLT, preconditioner first'
    if solver.max_slice_s is not None:
        return 'a solver with max_slice_s'
    return ''


@dataclass
class _Contacts:
    """A contact list as arrays for the compiled cycle (remade when the list changes)."""

    specs: list
    frame_ids: tuple[int, ...]
    links: tuple[str, ...]
    points: np.ndarray
    normals: np.ndarray
    has_normal: np.ndarray
    tangents: np.ndarray
    has_tangent: np.ndarray
    #: The links' frames as the compiled kinematics takes them (parent joints, placement
    #: rotations and translations), or None: Pinocchio's kinematics in Python.
    frames: tuple[np.ndarray, np.ndarray, np.ndarray] | None


class CompiledCycle:
    """
    The compiled cycle bound to one grasp's friction, weights, limits and one solver.

    Args:
        setup: the grasp (its friction, weights and limits are taken here).
        solver: the Python solver it stands in for (ProxSuite or DAQP): its settings are used,
            and its counters (``warm_solves``, ``fallbacks``, ``timeouts``) count the
            compiled solves too.
        tolerance: certificate tolerance.
        module: the compiled module to use (default: the best one built for this CPU).
        previous: the compiled cycle this one replaces (a squeeze or a parameter moved
            the grasp's constants): its hand's tree and checked links are kept when the
            hand is the same.
    """

    def __init__(self, setup: GraspSetup, solver: TauQPSolver, tolerance: float,
                 module=None, previous: CompiledCycle | None = None) -> None:
        self.solver = solver
        self.tolerance = tolerance
        #: What it was made for (held, so that an identity check cannot meet a new
        #: object at a freed one's address).
        self._made_for = (setup.hand, setup.friction, setup.weights, setup.objective, solver,
                          solver.settings, solver.warm_start, tolerance)
        hand = setup.hand
        friction = planned_friction(setup.friction)
        S_i, b_i = contact_block(friction.mu1, friction.mu2, friction.sides,
                                 friction.min_normal_force)
        daqp = isinstance(solver, daqp_backend.DaqpSolver)
        # DAQP's solve reads only the tolerances past max_iter_in here.
        st = ProxSuiteSettings() if daqp else solver.settings
        s = (module or fast_cycle).Settings()
        s.eps_abs, s.eps_rel, s.eps_primal_inf = st.eps_abs, st.eps_rel, st.eps_primal_inf
        s.max_iter, s.max_iter_in = st.max_iter, st.max_iter_in
        s.kkt_tolerance = daqp_backend.KKT_TOLERANCE if daqp else KKT_TOLERANCE
        s.certificate_tolerance = tolerance
        s.qr_rtol, s.box_margin = QR_RTOL, BOX_MARGIN
        s.inner_iteration_s, s.estimate_decay = INNER_ITERATION_S, ESTIMATE_DECAY
        s.primary_share = PRIMARY_SHARE
        #: The compiled module in use (``_fast_cycle`` or ``_fast_cycle_avx2``).
        self.module = module or fast_cycle
        self._cycle = self.module.FastCycle(
            np.asarray(hand.idx_v, dtype=np.int64), S_i, b_i,
            np.asarray(setup.weights, dtype=float), np.asarray(hand.torque_limits, dtype=float),
            friction.mu1, friction.mu2, setup.friction.mu1, setup.friction.mu2,
            friction.min_normal_force, solver.warm_start, s)
        if daqp:
            self._cycle.use_daqp(*daqp_backend.daqp_entry(), solver.settings.primal_tol,
                                 solver.settings.iter_limit, solver.settings.eq_reduction,
                                 daqp_backend.ITERATION_S)
        self._joints = list(hand.joints)
        self._contacts: _Contacts | None = None
        #: The hand's tree for the kinematics in the compiled call (None: Pinocchio's, in
        #: Python), and the contact links already held to Pinocchio's.
        self.tree: TreeKinematics | None = None
        self._tree_checked: set[int] = set()
        if previous is not None and previous._made_for[0] is hand \
                and previous.module is self.module:
            self.tree, self._tree_checked = previous.tree, previous._tree_checked
        else:
            try:
                self.tree = TreeKinematics(hand.model, self.module)
            except ValueError:  # not a tree of 1-DoF joints: Pinocchio's, in Python
                pass
        if self.tree is not None:
            self._cycle.use_tree(*self.tree.tables, hand.model.nq, hand.model.nv)
        self._no_offset = np.zeros(0)
        #: Cycles answered here, and handed back to the Python cycle (by reason code).
        self.solves = 0
        self.handed_back = 0
        #: Why the last cycle was handed back ('' if it was not).
        self.last_reason = ''
        #: The last cycle's outcome code (``fast_cycle.CERTIFIED`` ... ``TIMED_OUT``).
        self.last_code = 0
        #: Cycles in a row handed back for A's rank; at :data:`RANK_GIVE_UP`, ``gave_up``
        #: says why the compiled cycle is no longer tried for this grasp.
        self._rank_misses = 0
        self.gave_up = ''

    def fits(self, setup: GraspSetup, solver, tolerance: float) -> bool:
        """Tell whether this compiled cycle was made for this grasp's constants and solver."""
        hand, friction, weights, objective, made_solver, settings, warm, tol = self._made_for
        # The objects themselves, not equal copies (the hand, the weights and the solver
        # are the controller's until a parameter change replaces them); the frozen
        # friction and settings compare equal when they are copies.
        return (hand is setup.hand and weights is setup.weights and made_solver is solver
                and (friction is setup.friction or friction == setup.friction)
                and objective == setup.objective
                and (settings is solver.settings or settings == solver.settings)
                and warm == solver.warm_start and tol == tolerance)

    def _arrays(self, setup: GraspSetup) -> _Contacts:
        """Return the contact list as arrays, remade only when the list object changes."""
        c = self._contacts
        if c is not None and c.specs is setup.contacts:
            return c
        fids, links, points, normals, has_n, tangents, has_t = contact_arrays(
            setup.hand, setup.contacts)
        self._contacts = c = _Contacts(
            specs=setup.contacts, frame_ids=fids, links=links, points=points,
            normals=normals, has_normal=has_n, tangents=tangents, has_tangent=has_t,
            frames=self._frames(setup, fids))
        if c.frames is not None:  # held by the compiled cycle until the list changes
            self._cycle.bind_contacts(*c.frames, points, normals, has_n, tangents, has_t)
        return c

    def _frames(self, setup: GraspSetup, fids: tuple[int, ...]
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """Return the links' frame tables for the compiled kinematics, each link checked once."""
        tree = self.tree
        if tree is None:
            return None
        new = tuple(f for f in dict.fromkeys(fids) if f not in self._tree_checked)
        if new:
            try:  # at this configuration, against Pinocchio's own (the first time only)
                tree.check(np.array([setup.q]), new)
            except ValueError:
                self.tree = None  # never expected for a supported tree: Pinocchio's then
                return None
            self._tree_checked.update(new)
        return tree.frame_tables(fids)

    def kinematics(self, setup: GraspSetup, compute: bool = True
                   ) -> tuple[np.ndarray, np.ndarray]:
        """
        Return what the maps stage takes from Pinocchio: the contact links' placements, Jacobians.

        Args:
            setup: the grasp at its configuration.
            compute: compute the joint Jacobians and frame placements at ``setup.q``
                here; False: the hand's data already holds them.

        Returns:
            (oMf, shape (p, 4, 4), base frame; J6, shape (p, 6, nv),
            pinocchio.LOCAL_WORLD_ALIGNED at each link's origin).
        """
        c = self._arrays(setup)
        model, data = setup.hand.model, setup.hand.data
        if compute:
            pin.computeJointJacobians(model, data, setup.q)
            pin.updateFramePlacements(model, data)
        placements = data.oMf
        oMf = np.array([placements[fid].homogeneous for fid in c.frame_ids])
        J6 = np.array([pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
                       for fid in c.frame_ids])
        return oMf, J6

    def solve(self, setup: GraspSetup, time_left: float | None, kinematics: bool = True
              ) -> tuple[Solution, GraspMaps] | tuple[None, str]:
        """
        One cycle on the grasp at its configuration (contacts, load, torque offset set).

        Args:
            setup: the grasp of this cycle (``TorqueController.grasp_at``).
            time_left: seconds the solver may still take (None: only its caps).
            kinematics: compute the joint Jacobians and frame placements at
                ``setup.q`` here; False: the hand's data already holds them
                (``grasp_at(..., jacobians=True)``). Unused where the compiled call
                computes them (:attr:`tree`).

        Returns:
            (certified solution, maps), or (None, why) when the Python cycle must answer.
        """
        c = self._arrays(setup)
        offset = self._no_offset if setup.torque_offset is None else setup.torque_offset
        budget = -1.0 if time_left is None else time_left
        if c.frames is not None:
            a = self._cycle.solve_bound(setup.q, setup.object_origin, setup.external_wrench,
                                        offset, budget)
        else:
            oMf, J6 = self.kinematics(setup, kinematics)
            a = self._cycle.solve(oMf, J6, c.points, c.normals, c.has_normal, c.tangents,
                                  c.has_tangent, setup.object_origin, setup.external_wrench,
                                  offset, budget)
        solver = self.solver
        solver.warm_solves += a.warm_solves
        solver.fallbacks += a.redone_cold
        solver.last_warm = a.warm
        self.last_code = a.code
        if a.code != self.module.CERTIFIED:
            if isinstance(solver, TauQPSolver):  # DaqpSolver counts no timeouts
                solver.timeouts += a.code == self.module.TIMED_OUT
            self.handed_back += 1
            self.last_reason = f'compiled cycle: {a.message}'
            self._rank_misses = self._rank_misses + 1 if a.message.startswith('A = ') else 0
            if self._rank_misses >= RANK_GIVE_UP:
                self.gave_up = f'{a.message} in {RANK_GIVE_UP} cycles in a row'
            return None, self.last_reason
        self._rank_misses = 0
        self.solves += 1
        self.last_reason = ''
        tau, f, G, J, positions, rotations, usage, certificate, timings = a.parts
        maps = GraspMaps(G=G, J=J, links=c.links, frame_ids=c.frame_ids,
                         positions=positions, rotations=rotations,
                         object_origin=np.asarray(setup.object_origin, dtype=float))
        t_maps, t_build, t_solve, t_certify = timings
        eq, torque, cone, normal, limit, finite = certificate
        sol = Solution(status=OPTIMAL, method='tau-qp', joints=list(self._joints),
                       tau=tau, wrenches=f.reshape(-1, 4), iterations=a.iterations,
                       solve_time_s=a.solve_time_s,
                       certificate=Certificate(eq, torque, cone, normal, limit, finite,
                                               self.tolerance),
                       message=f'certified (solver: {a.message})',
                       timings={'maps': t_maps, 'build': t_build, 'solve': t_solve,
                                'certify': t_certify},
                       backend=solver.name, objective=setup.objective,
                       friction_margin=setup.friction.margin, friction_usage=usage,
                       max_torque_ratio=a.max_torque_ratio)
        return sol, maps
