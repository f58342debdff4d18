# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Small dense LPs for the planner's metrics: DAQP, KKT-checked, with SciPy HiGHS behind it.

The capacity and min-max LPs (docs/planner.md) have a few dozen variables and
about a hundred rows. DAQP solves them in tens of microseconds (SciPy's HiGHS:
about 3 ms through ``linprog``); an LP has a zero Hessian, which DAQP handles
by proximal-point iterations. No answer is trusted alone: DAQP's is checked
against the KKT conditions with its own multipliers
(:func:`grasp_torque_opt.backends.daqp.kkt_violation`, which with H = 0 proves
an LP optimum), and when that fails, or DAQP says infeasible or unbounded, HiGHS
solves the same LP and its verdict is taken. The callers certify the primal
answer against the exact problem as well.

Form (DAQP's): minimize c^T x subject to lower <= x <= upper (the first n
entries of ``lower``/``upper``) and lower <= A x <= upper (the rest); a row
with lower == upper is an equality. Infinite bounds are allowed.
"""

from __future__ import annotations

from dataclasses import dataclass
import time

from grasp_torque_opt.backends.daqp import (
    DAQP_INF,
    ITERATION_S,
    KKT_TOLERANCE,
    kkt_violation,
)
import numpy as np

#: DAQP's primal tolerance on these LPs (the backends' default eps_abs).
PRIMAL_TOL = 1e-9
#: Iteration cap of either solver: the LPs here need about a hundred.
MAX_ITER = 2000
#: DAQP's proximal weight for an LP (measured: 1e-4 to 1 all converge on the Allegro).
EPS_PROX = 1e-2


@dataclass(frozen=True)
class LPResult:
    """
    An LP's answer.

    Attributes:
        status: ``optimal``, ``infeasible``, ``unbounded`` or ``failed``.
        x: the primal solution, shape (n,), or None.
        lam: multipliers, shape (n + rows,): bounds on x first, then rows of A;
            > 0 where an upper bound binds, < 0 at a lower one (DAQP's sign; for
            HiGHS's answer the same convention), or None.
        solver: ``daqp`` or ``highs``.
        message: what happened, in words.
        solve_time_s: wall time of the solver calls [s].
    """

    status: str
    x: np.ndarray | None
    lam: np.ndarray | None
    solver: str
    message: str
    solve_time_s: float


class DaqpForm:
    """
    DAQP's view of the bounds: clipped to its infinity, equality flags, zero Hessian.

    Built once for LPs that differ only in A's entries (the 13 capacity LPs of a grasp).
    """

    def __init__(self, n: int, lower: np.ndarray, upper: np.ndarray) -> None:
        self.sense = np.zeros(lower.size, dtype=np.int32)
        self.sense[n:][lower[n:] == upper[n:]] = 5
        self.bu = np.minimum(upper, DAQP_INF)
        self.bl = np.maximum(lower, -DAQP_INF)
        self.H = np.zeros((n, n))


def solve_lp(c: np.ndarray, A: np.ndarray, lower: np.ndarray, upper: np.ndarray,
             highs_only: bool = False, form: DaqpForm | None = None,
             deadline: float | None = None, fallback: bool = True) -> LPResult:
    """
    Minimize c^T x subject to the bounds and rows of the module docstring.

    Args:
        c: cost, shape (n,).
        A: rows, shape (r, n).
        lower: lower bounds, shape (n + r,) (-inf allowed).
        upper: upper bounds, shape (n + r,) (inf allowed); lower == upper: equality.
        highs_only: skip DAQP (the fallback alone; tests and odd problems).
        form: the bounds in DAQP's form if already built (:class:`DaqpForm`).
        deadline: ``time.perf_counter()`` value by which to stop [s] (the node's cycle
            budget): DAQP's iterations fitted to the time left at an estimate of its
            time per iteration, HiGHS's ``time_limit`` the time left, none started
            past it (``failed``, "time budget spent"). None: the caps alone.
        fallback: HiGHS behind DAQP; False: DAQP's answer alone (``optimal``,
            KKT-checked; ``infeasible`` on its exit flag, which nothing confirms; else
            ``failed``), SciPy not imported.
    """
    t0 = time.perf_counter()
    why = ''
    if not highs_only:
        limit = MAX_ITER
        if deadline is not None:
            est = ITERATION_S * max(1.0, c.size * (c.size + A.shape[0]) / (16 * 144))
            limit = min(MAX_ITER, max(1, int((deadline - t0) / est)))
        out = _spent(deadline) or _daqp(c, A, form or DaqpForm(c.size, lower, upper), limit)
        if out is not None and out[0] == 'optimal':
            return LPResult('optimal', out[1], out[2], 'daqp', out[3],
                            time.perf_counter() - t0)
        why = out[3] if out is not None else 'DAQP raised'
        if not fallback:
            return LPResult(out[0] if out is not None else 'failed', None, None, 'daqp', why,
                            time.perf_counter() - t0)
    spent = _spent(deadline)
    if spent:
        return LPResult('failed', None, None, 'daqp', f'{spent[3]} (after DAQP: {why})',
                        time.perf_counter() - t0)
    res = _highs(c, A, lower, upper,
                 None if deadline is None else deadline - time.perf_counter())
    msg = res.message if not why else f'{res.message} (after DAQP: {why})'
    return LPResult(res.status, res.x, res.lam, 'highs', msg, time.perf_counter() - t0)


def linprog(*args, **kwargs):
    """Run SciPy's ``linprog`` (HiGHS), imported on first use: 0.3 s a plan never needs."""
    from scipy.optimize import linprog as highs

    return highs(*args, **kwargs)


def _spent(deadline: float | None):
    """Return the failure of an LP not started past ``deadline`` (None if there is time)."""
    if deadline is not None and time.perf_counter() >= deadline:
        return ('failed', None, None, 'time budget spent')
    return None


def _daqp(c, A, form: DaqpForm, limit: int | None = None):
    try:
        import daqp  # a selectable backend: a ROS distribution may not have it
    except ImportError:
        return ('failed', None, None, 'DAQP is not installed')

    H, bu, bl, sense = form.H, form.bu, form.bl, form.sense
    try:
        x, _, flag, info = daqp.solve(H, np.ascontiguousarray(c, dtype=float),
                                      np.ascontiguousarray(A, dtype=float), bu, bl, sense,
                                      primal_tol=PRIMAL_TOL, iter_limit=limit or MAX_ITER,
                                      eps_prox=EPS_PROX)
    except (RuntimeError, ValueError) as e:
        return ('failed', None, None, f'DAQP raised: {e}')
    if flag not in (1, 2) or x is None or not np.isfinite(x).all():
        return ('infeasible' if flag == -1 else 'failed', None, None, f'DAQP exit flag {flag}')
    lam = np.asarray(info['lam'], dtype=float)
    violation = kkt_violation(H, c, A, bl, bu, x, lam)
    if not violation <= KKT_TOLERANCE:
        return ('failed', None, None, f'DAQP answer off the KKT conditions by {violation:.2g}')
    return ('optimal', np.asarray(x, dtype=float), lam,
            f"DAQP optimal, KKT-checked ({info['iterations']} iterations)")


@dataclass(frozen=True)
class _Highs:
    status: str
    x: np.ndarray | None
    lam: np.ndarray | None
    message: str


def _highs(c, A, lower, upper, time_limit: float | None = None) -> _Highs:
    n, r = c.size, A.shape[0]
    lo_r, up_r = lower[n:], upper[n:]
    eq = lo_r == up_r
    has_up = ~eq & np.isfinite(up_r)
    has_lo = ~eq & np.isfinite(lo_r)
    A_ub = np.vstack((A[has_up], -A[has_lo]))
    b_ub = np.concatenate((up_r[has_up], -lo_r[has_lo]))
    bounds = [(None if not np.isfinite(lo) else lo, None if not np.isfinite(up) else up)
              for lo, up in zip(lower[:n], upper[:n])]
    res = linprog(c, A_ub=A_ub if A_ub.size else None, b_ub=b_ub if b_ub.size else None,
                  A_eq=A[eq] if eq.any() else None, b_eq=up_r[eq] if eq.any() else None,
                  bounds=bounds, method='highs',
                  options={'maxiter': MAX_ITER} if time_limit is None else
                  {'maxiter': MAX_ITER, 'time_limit': max(1e-6, time_limit)})
    status = {0: 'optimal', 2: 'infeasible', 3: 'unbounded'}.get(res.status, 'failed')
    if status != 'optimal':
        return _Highs(status, None, None, f'HiGHS: {res.message}')
    # HiGHS's marginals are d(objective)/d(bound), <= 0 on a binding upper bound of a
    # minimization: DAQP's lam is their negative.
    lam = np.zeros(n + r)
    lam[:n] = -(res.upper.marginals + res.lower.marginals)
    row = np.zeros(r)
    k_up = int(has_up.sum())
    marg = res.ineqlin.marginals if A_ub.size else np.zeros(0)
    row[has_up] -= marg[:k_up]
    row[has_lo] += marg[k_up:]
    if eq.any():
        row[eq] = -res.eqlin.marginals
    lam[n:] = row
    return _Highs('optimal', np.asarray(res.x, dtype=float), lam, 'HiGHS optimal')
