# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Load capacity: how many times over a grasp holds its load, and how much along each axis.

The capacity of a grasp for a load w_ext is the largest factor alpha such that
every load s w_ext with s in [0, alpha] is holdable within the torque limits and the
(margined) linearized cones (docs/planner.md). The loads a grasp holds along w_ext
form an interval (the constraints are convex), which need not contain zero: a grasp
whose contacts only balance a weight cannot squeeze at the minimum normal force
without it. So zero load is checked first (:meth:`CapacityLP.zero_load`, once per
grasp, a feasibility LP whose wrenches are certified at zero load); a grasp that
cannot hold it has capacity 0 (``infeasible``, with the infeasibility certificate of
:mod:`.infeasibility` saying why). Then the top of the interval is an LP over the
contact wrenches f and alpha:

    maximize    alpha
    subject to  G f + alpha w_ext = 0
                S f <= b                        polygon cones of the planned friction, f_z >= f_min
                tau_min <= J^T f <= tau_max     torque limits (after any offset g(q))
                0 <= alpha <= ALPHA_MAX

on the unit direction w_ext / max|w_ext| (alpha rescaled after, so that the LP's
numbers do not depend on the load's size). Solved by
:func:`grasp_torque_opt.methods.lp.solve_lp` (DAQP, KKT-checked, HiGHS behind it)
and certified like every other result: the f it returns is checked against the
exact problem at the load alpha w_ext (:func:`certify`). With the certified zero-load
wrenches f0, (1 - s/alpha) f0 + (s/alpha) f holds s w_ext for every s in [0, alpha]
(the exact cone is convex), so the grasp provably holds every load up to alpha times
its own. alpha < 1: the load itself cannot be held, and alpha is the largest
holdable fraction of it (:mod:`.explain` says what binds).

The 12 axis capacities are the same LP for the unit loads +-e_i, about the object
origin in base axes: +Fx is the largest force [N] along +x that the environment
may apply on the object (a weight with gravity along +x), +Mx the largest moment
[N m] about +x; the scenario's own load is replaced, not added.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from grasp_torque_opt.core.certificate import Certificate, certify, DEFAULT_TOLERANCE
from grasp_torque_opt.core.friction import friction_matrix
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.margin import planned_friction
from grasp_torque_opt.methods.infeasibility import Conflict, zero_load_conflict
from grasp_torque_opt.methods.lp import DaqpForm, LPResult, solve_lp
from grasp_torque_opt.reference.feasibility import linearized_feasible
import numpy as np

#: Cap on alpha, so that the LP stays bounded; reaching it reports ``unbounded``.
ALPHA_MAX = 1e6
#: The 12 axis directions: name -> (wrench index, sign); F in N, M in N m.
DIRECTIONS = {f'{s}{a}': (i, 1.0 if s == '+' else -1.0)
              for i, a in enumerate(('Fx', 'Fy', 'Fz', 'Mx', 'My', 'Mz')) for s in '+-'}
#: A multiplier counts as binding above this share of the largest one.
BINDING_RTOL = 1e-6


@dataclass(frozen=True)
class Binding:
    """
    What limits a capacity: the constraints with a nonzero multiplier at the LP optimum.

    Every one of them is active at every optimal point (complementary slackness).

    Attributes:
        joints: (joint name, ``upper`` or ``lower`` limit), largest multiplier first.
        contacts: (link, ``friction cone`` or ``min normal force``), largest first.
    """

    joints: list[tuple[str, str]] = field(default_factory=list)
    contacts: list[tuple[str, str]] = field(default_factory=list)

    def as_dict(self) -> dict:
        """Plain data (JSON)."""
        return {'joints': [{'joint': j, 'limit': s} for j, s in self.joints],
                'contacts': [{'link': c, 'constraint': s} for c, s in self.contacts]}

    def text(self) -> str:
        """One sentence: joints at their limit and contacts on their cone, by name."""
        parts = []
        if self.joints:
            parts.append('joints at their torque limit: ' + ', '.join(
                f'{j} ({s})' for j, s in self.joints))
        cones = [c for c, s in self.contacts if s == 'friction cone']
        normals = [c for c, s in self.contacts if s != 'friction cone']
        if cones:
            parts.append('contacts on their friction cone: ' + ', '.join(cones))
        if normals:
            parts.append('contacts at the minimum normal force: ' + ', '.join(normals))
        return '; '.join(parts) if parts else 'nothing identified'


@dataclass(frozen=True)
class Capacity:
    """
    One capacity.

    Attributes:
        status: ``optimal`` (certified), ``infeasible`` (not even zero load holds;
            confirmed by the independent feasibility LP, and ``binding`` and
            ``conflict`` from its infeasibility certificate, :mod:`.infeasibility`),
            ``unbounded`` (alpha reached :data:`ALPHA_MAX` on the unit direction, or the
            load is zero) or ``failed``.
        value: alpha: a factor on the load [-], or for an axis direction the largest
            load along it [N or N m], every smaller multiple held as well; 0 when
            ``infeasible``; None when ``unbounded`` or ``failed``.
        unit: ``-``, ``N`` or ``N m``.
        tau: joint torques holding value times the load [N m], or None.
        wrenches: the contact wrenches then, shape (p, 4) [N, N m], or None.
        certificate: of (tau, f) at the load value * w_ext, or None.
        binding: what limits it (``infeasible``: the constraints of the certificate),
            or None.
        solver: the LP solver that answered.
        message: what happened.
        conflict: ``infeasible`` only: the infeasibility certificate (its
            constraints, whether each constraint family's removal makes zero load
            holdable, whether the certificate checked); else None.
    """

    status: str
    value: float | None
    unit: str
    tau: np.ndarray | None = None
    wrenches: np.ndarray | None = None
    certificate: Certificate | None = None
    binding: Binding | None = None
    solver: str = ''
    message: str = ''
    conflict: Conflict | None = None

    def as_dict(self) -> dict:
        """
        Plain data (JSON): ``status``, ``value``, ``unit``, ``binding``, ``certified``.

        ``certified``: the certificate of the answer passed (``infeasible``: the
        infeasibility certificate checked).
        """
        certified = (self.certificate is not None and self.certificate.ok
                     or self.conflict is not None and self.conflict.certified)
        return {'status': self.status, 'value': self.value, 'unit': self.unit,
                'certified': certified,
                'binding': None if self.binding is None else self.binding.as_dict()}


class CapacityLP:
    """
    The capacity LP of one grasp, built once and solved for any load direction.

    Variables x = [f (4p); alpha]; rows: G f + alpha d = 0 (6), J^T f in the torque
    bounds (m), S f <= b (the planned polygons and f_min).

    ``explain``: name the conflict of a grasp that cannot hold zero load (False: the
    same verdict, certified the same way, without its name; the planner's filter).
    """

    def __init__(self, setup: GraspSetup, maps: GraspMaps,
                 tolerance: float = DEFAULT_TOLERANCE, explain: bool = True,
                 confirm: bool = True) -> None:
        self.setup, self.maps, self.tolerance = setup, maps, tolerance
        self.explain, self.confirm = explain, confirm
        self.friction = fr = planned_friction(setup.friction)
        G, J = maps.G, maps.J
        self.S, b_S = friction_matrix(maps.p, fr.mu1, fr.mu2, fr.sides, fr.min_normal_force)
        self.tau_min, self.tau_max = setup.tau_bounds
        nf, m = G.shape[1], J.shape[1]
        self.nf, self.m = nf, m
        n = nf + 1
        self.A = np.zeros((6 + m + self.S.shape[0], n))
        self.A[:6, :nf] = G
        self.A[6:6 + m, :nf] = J.T
        self.A[6 + m:, :nf] = self.S
        inf = np.inf
        self.lower = np.concatenate((np.full(nf, -inf), [0.0], np.zeros(6), self.tau_min,
                                     np.full(self.S.shape[0], -inf)))
        self.upper = np.concatenate((np.full(nf, inf), [ALPHA_MAX], np.zeros(6), self.tau_max,
                                     b_S))
        self.c = np.zeros(n)
        self.c[-1] = -1.0
        self.form = DaqpForm(n, self.lower, self.upper)
        # The zero-load LP: the same rows with alpha fixed at 0.
        self.zero_upper = self.upper.copy()
        self.zero_upper[nf] = 0.0
        self.zero_form = DaqpForm(n, self.lower, self.zero_upper)
        self.zero_form.sense[nf] = 5
        self._zero: dict[bool, Capacity | None] = {}

    def zero_load(self, highs_only: bool = False) -> Capacity | None:
        """
        Check that the grasp holds zero load (once per grasp; every direction shares it).

        The capacity LP's rows with alpha fixed at 0 (DAQP, KKT-checked, HiGHS behind
        it), the wrenches found certified at zero load.

        Returns:
            None when zero load is holdable (certified); else the capacity every load
            direction then has: ``infeasible`` (value 0, confirmed by the independent
            feasibility LP, the conflict from the infeasibility certificate) or
            ``failed`` (no certified answer either way).
        """
        if highs_only not in self._zero:
            self._zero[highs_only] = self._zero_load(highs_only)
        return self._zero[highs_only]

    def _zero_load(self, highs_only: bool) -> Capacity | None:
        confirm = self.confirm or highs_only
        res = solve_lp(self.c, self.A, self.lower, self.zero_upper, highs_only=highs_only,
                       form=self.zero_form, fallback=confirm)
        if res.status == 'optimal' and self._holds_zero(res.x[:self.nf]):
            return None
        if not confirm:  # DAQP's verdict alone (load_capacity's ``confirm``)
            if res.status == 'infeasible':
                return Capacity('infeasible', 0.0, '-', solver=res.solver, message=(
                    'not even zero load can be held, by DAQP alone (not confirmed)'))
            return Capacity('failed', None, '-', solver=res.solver,
                            message=f'zero load: {res.message} (not confirmed)')
        if res.solver == 'daqp' and not highs_only:
            res = solve_lp(self.c, self.A, self.lower, self.zero_upper, highs_only=True)
            if res.status == 'optimal' and self._holds_zero(res.x[:self.nf]):
                return None
        # Said only when the independent feasibility LP agrees that zero load cannot
        # be held (else the verdict is numerics, not the grasp).
        if linearized_feasible(self.maps, self.friction, np.zeros(6), self.tau_min,
                               self.tau_max) is False:
            if not self.explain:
                return Capacity('infeasible', 0.0, '-', solver=res.solver,
                                message='not even zero load can be held')
            return self._conflict(res)
        return Capacity('failed', None, '-', solver=res.solver, message=(
            f'zero load: {res.message}, and no certified answer (the feasibility LP does '
            'not confirm that zero load cannot be held)'))

    def _holds_zero(self, f: np.ndarray) -> bool:
        """Certify the wrenches f at zero load (the exact planned cone, f_min, limits)."""
        return certify(self.maps.G, self.maps.J, np.zeros(6), self.friction, self.tau_min,
                       self.tau_max, self.maps.J.T @ f, f, self.tolerance).ok

    def solve(self, load: np.ndarray, unit: str = '-', highs_only: bool = False,
              binding: bool = True) -> Capacity:
        """
        Find the largest alpha with alpha * load holdable, certified.

        Args:
            load: the load direction w_ext, shape (6,) [N, N m] (about the object
                origin, base axes).
            unit: unit of alpha, for the record.
            highs_only: solve with HiGHS alone.
            binding: name what binds (a batch that only ranks skips it: a third of
                the time of a capacity).
        """
        load = np.asarray(load, dtype=float)
        scale = float(np.abs(load).max())  # the max norm: no overflow at 1e300
        if not np.isfinite(scale):
            return Capacity('failed', None, unit, message='load not finite')
        zero = self.zero_load(highs_only)
        if zero is not None:  # no load range from zero: capacity 0, or no answer
            return dataclasses.replace(zero, unit=unit)
        if scale == 0.0:
            return Capacity('unbounded', None, unit, message=(
                'zero load: any multiple of it is the same load'))
        # The LP on the unit direction, alpha rescaled after: a load of 1e-6 or 1e6 N
        # gives the LP the same numbers.
        self.A[:6, -1] = load / scale
        res = solve_lp(self.c, self.A, self.lower, self.upper, highs_only=highs_only,
                       form=self.form)
        out = self._capacity(res, load, scale, unit, binding)
        if out.status == 'failed' and res.solver == 'daqp' and not highs_only:
            out = self._capacity(solve_lp(self.c, self.A, self.lower, self.upper,
                                          highs_only=True), load, scale, unit, binding)
        return out

    def _capacity(self, res: LPResult, load: np.ndarray, scale: float, unit: str,
                  binding: bool = True) -> Capacity:
        if res.status == 'infeasible':  # alpha = 0 is feasible (zero_load): numerics
            return Capacity('failed', None, unit, solver=res.solver, message=(
                f'{res.message}, although zero load is holdable (certified)'))
        if res.status != 'optimal':
            return Capacity('failed', None, unit, solver=res.solver, message=res.message)
        f, alpha = res.x[:self.nf], float(res.x[-1])
        if alpha >= (1.0 - 1e-9) * ALPHA_MAX:
            return Capacity('unbounded', None, unit, solver=res.solver, message=(
                f'alpha reached its cap {ALPHA_MAX:g}: the grasp holds this load '
                'direction without bound'))
        alpha /= scale
        tau = self.maps.J.T @ f
        cert = certify(self.maps.G, self.maps.J, alpha * load, self.friction, self.tau_min,
                       self.tau_max, tau, f, self.tolerance)
        if not cert.ok:
            return Capacity('failed', None, unit, certificate=cert, solver=res.solver,
                            message=f'{res.message}, certificate failed (worst residual '
                                    f'{cert.worst:.3g})')
        return Capacity('optimal', alpha, unit, tau=tau, wrenches=f.reshape(-1, 4),
                        certificate=cert, binding=self._binding(res, f) if binding else None,
                        solver=res.solver,
                        message=f'certified ({res.message})')

    def _conflict(self, res: LPResult) -> Capacity:
        """Zero load is not holdable: capacity 0, the conflict named from its certificate."""
        conflict = zero_load_conflict(self.maps, self.friction, list(self.setup.hand.joints),
                                      self.tau_min, self.tau_max)
        if conflict is None:
            return Capacity('infeasible', 0.0, '-', solver=res.solver, message=(
                'not even zero load can be held; no infeasibility certificate found '
                f'({res.message})'))
        return Capacity('infeasible', 0.0, '-', solver=res.solver,
                        binding=Binding(conflict.joints, conflict.contacts),
                        conflict=conflict,
                        message=conflict.text(self.friction.min_normal_force))

    def _binding(self, res: LPResult, f: np.ndarray) -> Binding:
        n = self.nf + 1
        lam = res.lam[n + 6:]  # the torque rows, then the friction rows
        scale = float(np.abs(lam).max()) if lam.size else 0.0
        if scale == 0.0:
            return Binding()
        thresh = BINDING_RTOL * scale
        m = self.m
        lam_tau, lam_S = lam[:m], lam[m:]
        joints = [(self.setup.hand.joints[j], 'upper' if lam_tau[j] > 0 else 'lower')
                  for j in np.argsort(-np.abs(lam_tau)) if abs(lam_tau[j]) > thresh]
        rows = self.S.shape[0] // self.maps.p
        per_contact: dict[tuple[int, str], float] = {}
        for r in np.flatnonzero(np.abs(lam_S) > thresh):
            i, kind = divmod(int(r), rows)
            key = (i, 'min normal force' if kind == rows - 1 else 'friction cone')
            per_contact[key] = per_contact.get(key, 0.0) + abs(float(lam_S[r]))
        contacts = [(self.maps.links[i], kind) for (i, kind), _ in
                    sorted(per_contact.items(), key=lambda kv: -kv[1])]
        return Binding(joints, contacts)


def load_capacity(setup: GraspSetup, maps: GraspMaps | None = None,
                  load: np.ndarray | None = None, highs_only: bool = False,
                  explain: bool = True, confirm: bool = True) -> Capacity:
    """
    How many times over the grasp holds its load (alpha [-], certified).

    Args:
        setup: the grasp (its friction margin and torque offset apply).
        maps: G and J if already computed.
        load: w_ext instead of the setup's load [N, N m].
        highs_only: HiGHS alone, no DAQP.
        explain: name what binds, or the conflict when not even zero load is held
            (False: the same verdict, certified the same way, unnamed; the planner's
            filter).
        confirm: a zero load DAQP does not hold is confirmed by HiGHS (as the rest of
            the LPs' fallback) and by the independent feasibility LP before it is called
            ``infeasible``. False: DAQP's verdict alone (``infeasible`` on its exit
            flag, else ``failed``), no SciPy imported: for a filter that only drops
            what is not certified held (the planner's, which keeps only a certified
            capacity of at least 1). Every other answer is the same either way.
    """
    lp = CapacityLP(setup, maps if maps is not None else setup.maps(), explain=explain,
                    confirm=confirm)
    return lp.solve(setup.external_wrench if load is None else load, '-', highs_only,
                    binding=explain)


def direction_capacities(setup: GraspSetup, maps: GraspMaps | None = None,
                         lp: CapacityLP | None = None, binding: bool = True
                         ) -> dict[str, Capacity]:
    """
    Find the largest load along each of the 12 axis directions (:data:`DIRECTIONS`).

    Args:
        setup: the grasp.
        maps: G and J if already computed.
        lp: the grasp's capacity LP if already built.
        binding: name what binds each (see :meth:`CapacityLP.solve`).

    Returns:
        Direction name -> capacity; forces in N, moments in N m.
    """
    lp = lp or CapacityLP(setup, maps if maps is not None else setup.maps())
    out = {}
    for name, (i, sign) in DIRECTIONS.items():
        d = np.zeros(6)
        d[i] = sign
        out[name] = lp.solve(d, 'N' if i < 3 else 'N m', binding=binding)
    return out
