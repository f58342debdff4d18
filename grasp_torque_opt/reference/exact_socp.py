# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Reference method (b): the exact soft-finger cone as an SOCP (Clarabel).

sqrt(fx^2 + fy^2)/mu1 + |mz|/mu2 <= fz holds iff some s_i satisfies
||(fx, fy)|| <= mu1 s_i and |mz| <= mu2 (fz - s_i). Over x = [f; s]:

    minimize    f^T J W J^T f
    subject to  G f + w_ext = 0
                (mu1 s_i, fx_i, fy_i) in the second-order cone
                |mz_i| <= mu2 (fz_i - s_i),  fz_i >= f_min
                tau_min <= J^T f <= tau_max

Its optimum is a lower bound for every polygon method (the inscribed polygon
is an inner approximation of the cone).
"""

from __future__ import annotations

import clarabel
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.scenario import Friction
from grasp_torque_opt.core.solution import RawResult
from grasp_torque_opt.reference.conic import solve_conic
import numpy as np


def solve_exact_socp(maps: GraspMaps, friction: Friction, external_wrench: np.ndarray,
                     tau_min: np.ndarray, tau_max: np.ndarray,
                     weights: np.ndarray) -> RawResult:
    """Solve the exact-cone SOCP; ``x`` of the result is [f (4p); s (p)]."""
    G, J = maps.G, maps.J
    p, m = maps.p, J.shape[1]
    n = 5 * p
    mu1, mu2 = friction.mu1, friction.mu2
    P = np.zeros((n, n))
    P[:4 * p, :4 * p] = 2.0 * J @ np.diag(weights) @ J.T

    lin_rows, lin_rhs, soc_rows = [], [], []
    for i in range(p):
        fx, fy, fz, mz, s = 4 * i, 4 * i + 1, 4 * i + 2, 4 * i + 3, 4 * p + i
        row = np.zeros(n)
        row[fz] = -1.0
        lin_rows.append(row)
        lin_rhs.append(-friction.min_normal_force)
        for sign in (1.0, -1.0):
            row = np.zeros(n)
            row[mz], row[fz], row[s] = sign, -mu2, mu2
            lin_rows.append(row)
            lin_rhs.append(0.0)
        block = np.zeros((3, n))
        block[0, s], block[1, fx], block[2, fy] = -mu1, -1.0, -1.0
        soc_rows.append(block)
    JT = np.hstack((J.T, np.zeros((m, p))))
    A = np.vstack([np.hstack((G, np.zeros((6, p)))), *lin_rows, JT, -JT, *soc_rows])
    b = np.concatenate((-external_wrench, lin_rhs, tau_max, -tau_min,
                        np.zeros(3 * p)))
    cones = ([clarabel.ZeroConeT(6), clarabel.NonnegativeConeT(3 * p + 2 * m)]
             + [clarabel.SecondOrderConeT(3) for _ in range(p)])
    return solve_conic(P, np.zeros(n), A, b, cones)
