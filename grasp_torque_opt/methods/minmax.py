# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The min-max torque objective (the paper's future work): an LP, then the sum of squares.

    minimize    t = max_i w_i |tau_i + offset_i| / limit_i
    subject to  the tau-QP's constraints (cones, compatibility, torque box)

is an LP over [tau; z; t], solved on the built tau-QP's own data
(:func:`grasp_torque_opt.methods.lp.solve_lp`: DAQP KKT-checked, HiGHS behind
it). Its torque optimum is not unique (only the largest ratio is minimized), so
the answer is made unique, and minimum-effort among the min-max optima, by the
tau-QP itself with its box tightened to w_i |tau_i + offset_i| <= t* limit_i
(with :data:`SLACK` of room for the LP's tolerance); the dispatcher then certifies
that answer against the *original* limits as for every result. W weighs both
stages: in the LP a joint's ratio counts w_i times, in the QP its square.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from grasp_torque_opt.core.tau_qp import TauQP
from grasp_torque_opt.methods.lp import solve_lp
import numpy as np

#: Relative room on t* for the second stage (the LP is solved to 1e-9).
SLACK = 1e-7


@dataclass(frozen=True)
class MinMax:
    """
    The LP stage.

    Attributes:
        status: the LP's status (``optimal``, ``infeasible``, ``unbounded``, ``failed``).
        value: t*, the smallest max_i w_i |tau_i + offset_i| / limit_i [-], or None.
        qp: the tau-QP with its box tightened to t*, or the input QP when not optimal.
        message: what happened.
    """

    status: str
    value: float | None
    qp: TauQP
    message: str


def minmax_stage(qp: TauQP, limits: np.ndarray, weights: np.ndarray,
                 offset: np.ndarray | None = None, deadline: float | None = None) -> MinMax:
    """
    Solve the min-max LP on a built tau-QP and tighten its torque box to the optimum.

    Args:
        qp: the tau-QP (sum-of-squares objective; only its constraints are used here).
        limits: torque limits, shape (m,) [N m].
        weights: W's diagonal, shape (m,), > 0.
        offset: torque added before commanding (g(q)), shape (m,) [N m], or None.
        deadline: ``time.perf_counter()`` value by which the LP stops [s]
            (:func:`~grasp_torque_opt.methods.lp.solve_lp`); None: its caps alone.
    """
    m, n = qp.m, qp.H.shape[0]
    off = np.zeros(m) if offset is None else np.asarray(offset, dtype=float)
    lim = np.asarray(limits, dtype=float)
    w = np.asarray(weights, dtype=float)
    n_eq, n_in = qp.A.shape[0], qp.C.shape[0]
    A = np.zeros((n_eq + n_in + 2 * m, n + 1))
    A[:n_eq, :n] = qp.A
    A[n_eq:n_eq + n_in, :n] = qp.C
    rows = n_eq + n_in + np.arange(m)
    A[rows, np.arange(m)] = w
    A[rows, n] = -lim
    A[rows + m, np.arange(m)] = -w
    A[rows + m, n] = -lim
    inf = np.inf
    lower = np.concatenate((qp.l_box, [0.0], qp.b, np.full(n_in + 2 * m, -inf)))
    upper = np.concatenate((qp.u_box, [inf], qp.b, qp.u, -w * off, w * off))
    c = np.zeros(n + 1)
    c[-1] = 1.0
    res = solve_lp(c, A, lower, upper, deadline=deadline)
    if res.status != 'optimal':
        return MinMax(res.status, None, qp, f'min-max LP {res.status}: {res.message}')
    t = float(res.x[-1])
    reach = (t * (1.0 + SLACK) + 1e-12) * lim / w
    l_box, u_box = qp.l_box.copy(), qp.u_box.copy()
    l_box[:m] = np.maximum(l_box[:m], -reach - off)
    u_box[:m] = np.minimum(u_box[:m], reach - off)
    return MinMax('optimal', t, dataclasses.replace(qp, l_box=l_box, u_box=u_box),
                  f'min-max LP t* = {t:.6g} ({res.message})')
