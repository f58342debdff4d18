# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Full metrics of many candidates: their 14 capacity LPs solved and checked in one compiled call.

For each candidate the batch stages (:mod:`.batch`) certified: its zero-load LP, the
load capacity and the 12 axis capacities of :mod:`.capacity`, the same LPs solved the
same way: DAQP as :func:`grasp_torque_opt.methods.lp.solve_lp` calls it, on the rows and
bounds of :class:`~grasp_torque_opt.methods.capacity.CapacityLP`. The compiled batch
(``capacity_batch``, src/fast_batch.hpp) runs them all: it writes each LP's rows in
place, calls DAQP's C entry (``daqp_quadprog``, the function ``daqp.solve`` runs, found
in the daqp module's own extension: :func:`~grasp_torque_opt.backends.daqp.daqp_entry`),
and checks each answer as the single path does in Python (the KKT check with DAQP's
multipliers, alpha, the certificate of the answer at alpha times the load, and the
zero-load LP's wrenches certified at zero load). The axes go first: where an axis's
answer holds alpha = 0, or two opposite axes' answers f+ (alpha+ e) and f- (alpha- (-e))
combine into (alpha- f+ + alpha+ f-) / (alpha+ + alpha-), which holds zero load (the
cones and limits are convex) and is certified there, zero load is held and its LP is not
solved. Where the installed daqp is not a release whose C structs the compiled batch
declares (:data:`~grasp_torque_opt.backends.daqp.DAQP_C_VERSIONS`), the LPs are solved
from Python one ``daqp.solve`` each, their checks in one compiled call per few
candidates (``lp_finish_batch``). Either way an LP whose answer does not pass, or that
DAQP does not call optimal, is solved again by the single path's
:meth:`CapacityLP.solve` (HiGHS behind DAQP, the unbounded and infeasible verdicts),
whose answer is then the value; so are all of a candidate's LPs when its zero-load LP
does not pass.

Since API 5 the compiled batch first tries the vertex method of src/vertex_lp.hpp (a
primal active-set LP solver, written for these LPs because they share a start: phase 1
finds each candidate's zero-load wrenches, certified at zero load, and every LP of the
candidate starts from that vertex at alpha = 0, over the null space of its wrench
balance: about 16 pivots where DAQP takes about fifty iterations from scratch). Its
answers go through the same KKT check and certificate (the equalities' multipliers
recovered for it); an LP it does not answer is DAQP's as above. The axes are solved
before the load: where the load's direction W / max |W| is exactly one of the axes (a
weight at the object's origin, as on every planned line), the load's LP is that axis's
LP, and the axis's answer is checked for the load (KKT, alpha = x_alpha / max |W|, the
certificate at alpha W) instead of being solved again: 12 LPs solved, not 13.
"""

from __future__ import annotations

from collections.abc import Callable
import math

from grasp_torque_opt.backends.daqp import daqp_entry, KKT_TOLERANCE
from grasp_torque_opt.methods.capacity import ALPHA_MAX, CapacityLP, DIRECTIONS
from grasp_torque_opt.methods.lp import EPS_PROX, MAX_ITER, PRIMAL_TOL
import numpy as np

#: The 13 loads: the candidate's own (None here), then the 12 axis directions.
LOADS = (('load', None, '-'),) + tuple(
    (name, (i, sign), 'N' if i < 3 else 'N m') for name, (i, sign) in DIRECTIONS.items())
#: The 12 axis loads, in :data:`LOADS`' order, shape (12, 6).
AXES = np.array([[sign if j == i else 0.0 for j in range(6)]
                 for i, sign in DIRECTIONS.values()])
#: Candidates whose LPs are checked in one compiled call (bounded memory).
PER_CALL = 16


class CapacityBatch:
    """
    The capacity LPs of many candidates of one hand (one contact count per call).

    Args:
        cycle: the batch stages' compiled cycle (its friction, limits, tolerance).
    """

    def __init__(self, cycle) -> None:
        import daqp

        self._solve = daqp.solve
        self.cycle = cycle
        self._forms: dict[int, CapacityLP] = {}
        #: DAQP's C entry points for the compiled LPs (None: solved from Python).
        self.entry = daqp_entry() if hasattr(cycle, 'capacity_batch') else None
        #: LPs solved again by the single path (their answer here did not pass).
        self.redone = 0

    def metrics(self, G: np.ndarray, J: np.ndarray, W: np.ndarray,
                bound: Callable[[int], tuple]) -> list[dict]:
        """
        Return the full metrics of candidates (as :meth:`Scorer.capacities` of optimal ones).

        Args:
            G: their grasp matrices, shape (n, 6, 4p).
            J: their hand Jacobians, shape (n, 4p, m).
            W: their loads, shape (n, 6).
            bound: candidate index -> (setup, maps) as the single path binds it (for
                :class:`CapacityLP`, the template and the LPs that do not pass).
        """
        n = G.shape[0]
        if self.entry is not None and n:
            return self._compiled(G, J, W, bound)
        out = []
        for start in range(0, n, PER_CALL):
            stop = min(n, start + PER_CALL)
            out.extend(self._some(G, J, W, bound, start, stop))
        return out

    def _template(self, bound, p: int) -> CapacityLP:
        lp = self._forms.get(p)
        if lp is None:
            lp = self._forms[p] = CapacityLP(*bound(0))
        return lp

    def _compiled(self, G, J, W, bound) -> list[dict]:
        """Solve and check every LP in one compiled call (DAQP's C entry: ``daqp_entry``)."""
        nf, m = G.shape[2], J.shape[2]
        t = self._template(bound, nf // 4)
        form, zero = t.form, t.zero_form
        out = self.cycle.capacity_batch(
            *self.entry, G, J, W, AXES, np.ascontiguousarray(t.A[6 + m:, :nf]), form.bl,
            form.bu, form.sense, zero.bl, zero.bu, zero.sense, PRIMAL_TOL, MAX_ITER,
            EPS_PROX, KKT_TOLERANCE, ALPHA_MAX)
        passes, alpha = out['passes'].tolist(), out['alpha'].tolist()
        return [self._candidate(i, passes[i][0], passes[i][1:], alpha[i][1:], W, bound)
                for i in range(G.shape[0])]

    def _candidate(self, i: int, zero: bool, passes: list, alpha: list, W, bound) -> dict:
        """
        Return candidate i's full metrics from its LPs' answers (:data:`LOADS`' order).

        An LP that did not pass, or every LP when the zero-load LP did not, is the single
        path's (:meth:`CapacityLP.solve`).
        """
        lp = None
        values, statuses, reasons = {}, {}, {}
        for j, (name, axis, unit) in enumerate(LOADS):
            if passes[j] and zero:
                values[name], statuses[name], reasons[name] = alpha[j], 'optimal', None
                continue
            if lp is None:  # the single path's LP of this candidate, and its verdict
                lp = CapacityLP(*bound(i))
            self.redone += 1
            if axis is None:
                load = W[i]
            else:
                load = np.zeros(6)
                load[axis[0]] = axis[1]
            cap = lp.solve(load, unit, binding=False)
            values[name], statuses[name] = cap.value, cap.status
            reasons[name] = None if cap.status == 'optimal' else cap.message
        return {'capacity': values['load'], 'capacity_status': statuses['load'],
                'capacity_reason': reasons['load'], 'holdable_fraction': None,
                'capacities': {name: values[name] for name in DIRECTIONS}}

    def _some(self, G, J, W, bound, start: int, stop: int) -> list[dict]:
        nf = G.shape[2]
        m = J.shape[2]
        t = self._template(lambda _: bound(start), nf // 4)
        form, c = t.form, t.c
        rows, cols = t.A.shape
        count = (stop - start) * len(LOADS)
        A = np.zeros((count, rows, cols))
        A[:, :6, :nf] = np.repeat(G[start:stop], len(LOADS), axis=0)
        A[:, 6:6 + m, :nf] = np.repeat(J[start:stop].transpose(0, 2, 1), len(LOADS), axis=0)
        A[:, 6 + m:, :nf] = t.A[6 + m:, :nf]
        loads = np.zeros((count, 6))
        scale = np.ones(count)
        x = np.zeros((count, cols))
        lam = np.zeros((count, cols + rows))
        ok = np.zeros(count, dtype=bool)
        usable = np.ones(count, dtype=bool)
        solve, H, bu, bl, sense = self._solve, form.H, form.bu, form.bl, form.sense
        for k in range(count):
            i, j = divmod(k, len(LOADS))
            axis = LOADS[j][1]
            if axis is None:
                load = W[start + i]
                s = float(np.abs(load).max())
                if not (math.isfinite(s) and s > 0.0):
                    usable[k] = False  # failed or unbounded: the single path says which
                    continue
                loads[k], scale[k] = load, s
                A[k, :6, -1] = load / s
            else:
                loads[k, axis[0]] = A[k, axis[0], -1] = axis[1]
            try:
                xk, _, flag, info = solve(H, c, A[k], bu, bl, sense, primal_tol=PRIMAL_TOL,
                                          iter_limit=MAX_ITER, eps_prox=EPS_PROX)
            except (RuntimeError, ValueError):
                continue
            if flag in (1, 2) and xk is not None:
                x[k], lam[k] = xk, info['lam']
                ok[k] = bool(np.isfinite(x[k]).all())
        cand = np.repeat(np.arange(start, stop, dtype=np.int64), len(LOADS))
        fin = self.cycle.lp_finish_batch(G, J, cand, loads, scale, A, bl, bu, c, x, lam, ok,
                                         KKT_TOLERANCE, ALPHA_MAX)
        passes, alpha = fin['passes'].tolist(), fin['alpha'].tolist()
        zero = self._zero_holds(G, J, np.ascontiguousarray(A[::len(LOADS)]), t, start, stop)
        k = len(LOADS)
        return [self._candidate(start + i, zero[i],
                                [p and u for p, u in zip(passes[k * i:k * (i + 1)],
                                                         usable[k * i:k * (i + 1)].tolist())],
                                alpha[k * i:k * (i + 1)], W, bound)
                for i in range(stop - start)]

    def _zero_holds(self, G, J, A, t: CapacityLP, start: int, stop: int) -> list[bool]:
        """
        Say, per candidate, whether its zero-load LP passes (DAQP, the KKT check, certified).

        The capacity LP's rows with alpha fixed at 0 (:meth:`CapacityLP.zero_load`); a
        candidate that does not pass takes the single path for all its LPs.
        """
        form, c = t.zero_form, t.c
        count, cols = A.shape[0], A.shape[2]
        x = np.zeros((count, cols))
        lam = np.zeros((count, cols + A.shape[1]))
        ok = np.zeros(count, dtype=bool)
        for k in range(count):
            try:
                xk, _, flag, info = self._solve(form.H, c, A[k], form.bu, form.bl, form.sense,
                                                primal_tol=PRIMAL_TOL, iter_limit=MAX_ITER,
                                                eps_prox=EPS_PROX)
            except (RuntimeError, ValueError):
                continue
            if flag in (1, 2) and xk is not None:
                x[k], lam[k] = xk, info['lam']
                ok[k] = bool(np.isfinite(x[k]).all())
        fin = self.cycle.lp_finish_batch(G, J, np.arange(start, stop, dtype=np.int64),
                                         np.zeros((count, 6)), np.ones(count), A, form.bl,
                                         form.bu, c, x, lam, ok, KKT_TOLERANCE, ALPHA_MAX)
        return fin['passes'].tolist()
