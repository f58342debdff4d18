# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Independent feasibility check of the linearized problem: an LP (SciPy HiGHS).

A solver's "infeasible" is never trusted alone: before a polygon method
reports ``infeasible``, this LP must agree that no f satisfies
G f + w_ext = 0, S f <= b and tau_min <= J^T f <= tau_max. With the
circumscribed polygon (an outer approximation), "infeasible" holds for the
exact cone too (``tau-qp-adaptive``'s infeasible verdict).
"""

from __future__ import annotations

from grasp_torque_opt.core.friction import circumscribed_rows, friction_matrix
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.scenario import Friction
import numpy as np


def linearized_feasible(maps: GraspMaps, friction: Friction, external_wrench: np.ndarray,
                        tau_min: np.ndarray, tau_max: np.ndarray,
                        circumscribed: bool = False) -> bool | None:
    """
    Whether some contact wrench holds the load within the polygon and the limits.

    Args:
        circumscribed: the N-gon scaled by 1/cos(pi/N) (it contains the exact
            cone) instead of the paper's inscribed one.

    Returns:
        True or False as HiGHS proves it, None if HiGHS could not decide.
    """
    G, J = maps.G, maps.J
    S, b_S = friction_matrix(maps.p, friction.mu1, friction.mu2, friction.sides,
                             friction.min_normal_force)
    if circumscribed:
        block = np.vstack((circumscribed_rows(friction.mu1, friction.mu2, friction.sides),
                           [0.0, 0.0, -1.0, 0.0]))
        S = np.kron(np.eye(maps.p), block)
    # Imported here, not from methods.lp's lazy one: the reference stays apart from methods.
    from scipy.optimize import linprog  # on first use: 0.3 s of imports
    res = linprog(np.zeros(G.shape[1]), A_ub=np.vstack((S, J.T, -J.T)),
                  b_ub=np.concatenate((b_S, tau_max, -tau_min)),
                  A_eq=G, b_eq=-external_wrench, bounds=(None, None), method='highs')
    return {0: True, 2: False}.get(res.status)
