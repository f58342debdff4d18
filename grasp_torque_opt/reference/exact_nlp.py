# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Reference method (c): an iterative nonlinear solve of the exact cone (SciPy SLSQP).

A stand-in for the paper's reference [6]. Over x = [f; s], with the smooth
form of the exact cone:

    minimize    f^T J W J^T f
    subject to  G f + w_ext = 0
                mu1 s_i - ||(fx_i, fy_i)|| >= 0,      s_i >= 0
                mu2 (fz_i - s_i) -+ mz_i >= 0,        fz_i >= f_min
                tau_max - J^T f >= 0,  J^T f - tau_min >= 0

It starts from the least-norm balancing wrench with every normal force raised
to f_min + 1 N, not from another method's answer.
"""

from __future__ import annotations

import time

from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.scenario import Friction
from grasp_torque_opt.core.solution import RawResult
import numpy as np
from scipy.optimize import minimize

#: Smoothing of ||(fx, fy)|| at 0 [N]; the smoothed cone is inside the exact one.
EPS = 1e-9


def solve_exact_nlp(maps: GraspMaps, friction: Friction, external_wrench: np.ndarray,
                    tau_min: np.ndarray, tau_max: np.ndarray, weights: np.ndarray,
                    max_iter: int = 500) -> RawResult:
    """Solve the exact-cone problem with SLSQP; ``x`` of the result is [f (4p); s (p)]."""
    G, J = maps.G, maps.J
    p = maps.p
    mu1, mu2 = friction.mu1, friction.mu2
    Q = 2.0 * J @ np.diag(weights) @ J.T
    ix, iy, iz, im = (np.arange(p) * 4 + k for k in range(4))
    i_s = 4 * p + np.arange(p)
    n = 5 * p

    def objective(x):
        f = x[:4 * p]
        return 0.5 * f @ Q @ f, np.concatenate((Q @ f, np.zeros(p)))

    def ineq(x):
        fx, fy, fz, mz, s = x[ix], x[iy], x[iz], x[im], x[i_s]
        tau = J.T @ x[:4 * p]
        return np.concatenate((mu1 * s - np.sqrt(fx ** 2 + fy ** 2 + EPS ** 2) + EPS, s,
                               mu2 * (fz - s) - mz, mu2 * (fz - s) + mz,
                               fz - friction.min_normal_force,
                               tau_max - tau, tau - tau_min))

    def ineq_jac(x):
        rows = np.zeros((5 * p, n))
        r = np.arange(p)
        norm = np.sqrt(x[ix] ** 2 + x[iy] ** 2 + EPS ** 2)
        rows[r, ix], rows[r, iy], rows[r, i_s] = -x[ix] / norm, -x[iy] / norm, mu1
        rows[p + r, i_s] = 1.0
        rows[2 * p + r, iz], rows[2 * p + r, i_s], rows[2 * p + r, im] = mu2, -mu2, -1.0
        rows[3 * p + r, iz], rows[3 * p + r, i_s], rows[3 * p + r, im] = mu2, -mu2, 1.0
        rows[4 * p + r, iz] = 1.0
        JT = np.hstack((J.T, np.zeros((J.shape[1], p))))
        return np.vstack((rows, -JT, JT))

    Gx = np.hstack((G, np.zeros((6, p))))
    f0 = np.linalg.lstsq(G, -external_wrench, rcond=None)[0]
    f0[iz] = np.maximum(f0[iz], friction.min_normal_force + 1.0)
    x0 = np.concatenate((f0, 0.5 * f0[iz]))
    t0 = time.perf_counter()
    res = minimize(objective, x0, jac=True, method='SLSQP',
                   constraints=[{'type': 'eq', 'fun': lambda x: Gx @ x + external_wrench,
                                 'jac': lambda x: Gx},
                                {'type': 'ineq', 'fun': ineq, 'jac': ineq_jac}],
                   options={'ftol': 1e-10, 'maxiter': max_iter})
    elapsed = time.perf_counter() - t0
    return RawResult('solved' if res.success else 'error', np.array(res.x), int(res.nit),
                     elapsed, str(res.message))
