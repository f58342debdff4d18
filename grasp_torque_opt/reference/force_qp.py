# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Reference method (a): optimize in contact-force space, then tau = J^T f.

    minimize    f^T f            (objective "force": the classic method)
           or   f^T J W J^T f    (objective "torque": same optimum as the tau-QP)
    subject to  G f + w_ext = 0,  S f <= b,  tau_min <= J^T f <= tau_max

The polygon, the normal bound and the torque limits are the tau-QP's, so the
two methods search the same set; only the objective (and the solver,
Clarabel) differs.
"""

from __future__ import annotations

import clarabel
from grasp_torque_opt.core.friction import friction_matrix
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.scenario import Friction
from grasp_torque_opt.core.solution import RawResult
from grasp_torque_opt.reference.conic import solve_conic
import numpy as np

OBJECTIVES = ('force', 'torque')


def solve_force_qp(maps: GraspMaps, friction: Friction, external_wrench: np.ndarray,
                   tau_min: np.ndarray, tau_max: np.ndarray, weights: np.ndarray,
                   objective: str = 'force') -> RawResult:
    """Solve the force-space QP; ``x`` of the result is f, shape (4p,)."""
    if objective not in OBJECTIVES:
        raise ValueError(f'objective must be one of {OBJECTIVES}, got {objective!r}')
    G, J = maps.G, maps.J
    n = G.shape[1]
    S, b_S = friction_matrix(maps.p, friction.mu1, friction.mu2, friction.sides,
                             friction.min_normal_force)
    P = 2.0 * (np.eye(n) if objective == 'force' else J @ np.diag(weights) @ J.T)
    A = np.vstack((G, S, J.T, -J.T))
    b = np.concatenate((-external_wrench, b_S, tau_max, -tau_min))
    cones = [clarabel.ZeroConeT(6), clarabel.NonnegativeConeT(len(b) - 6)]
    return solve_conic(P, np.zeros(n), A, b, cones)
