# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Coupled hands written as joint torques with the coupling as equality constraints.

Independent of the package's velocity map C: every joint of the hand is a column of the
uncoupled Jacobian J (4p x n), each actuator drives its own joint only (S, n x m, a
column selection) and each coupling q_f = k q_t + b is a mechanism whose reaction
lambda acts along its constraint row a = e_f - k e_t (A, r x n). Static equilibrium of
the fingers: J^T f = S u + A^T lambda, with u the actuator torques.
"""

import clarabel
from independent import polygon_rows
import numpy as np
from scipy import sparse
from scipy.optimize import linprog


def mechanism(joints, actuators, couplings):
    """
    S (n x m) and A (r x n) for joints in the uncoupled Jacobian's column order.

    Args:
        joints: the uncoupled hand's joints (its Jacobian's columns).
        actuators: the coupled hand's actuators.
        couplings: (follower, target, multiplier) triples.
    """
    n = len(joints)
    S = np.zeros((n, len(actuators)))
    for k, a in enumerate(actuators):
        S[joints.index(a), k] = 1.0
    A = np.zeros((len(couplings), n))
    for r, (f, t, k) in enumerate(couplings):
        A[r, joints.index(f)] = 1.0
        A[r, joints.index(t)] = -k
    return S, A


def _rows(setup, maps, S, A):
    """Equality rows on x = [u, lambda, f] and the polygon rows, shared by QP and LPs."""
    fr = setup.friction
    P_i, b_i = polygon_rows(fr.mu1, fr.mu2, fr.sides, fr.min_normal_force)
    p = maps.p
    m, r = S.shape[1], A.shape[0]
    poly = np.hstack((np.zeros((p * P_i.shape[0], m + r)), np.kron(np.eye(p), P_i)))
    eq = np.vstack((np.hstack((np.zeros((6, m + r)), maps.G)),
                    np.hstack((-S, -A.T, maps.J.T))))
    return eq, poly, np.tile(b_i, p)


def coupled_qp(setup, maps, S, A, limits):
    """
    Minimize sum u^2 with Clarabel; return u (or None if not solved).

    ``setup``, ``maps``: the *uncoupled* hand (all joints as columns) at the grasp.
    """
    m = S.shape[1]
    eq, poly, b_poly = _rows(setup, maps, S, A)
    nx = eq.shape[1]
    box = np.zeros((2 * m, nx))
    box[:m, :m], box[m:, :m] = np.eye(m), -np.eye(m)
    Aall = sparse.csc_matrix(np.vstack((eq, poly, box)))
    b = np.concatenate((-setup.external_wrench, np.zeros(eq.shape[0] - 6), b_poly,
                        limits, limits))
    P = np.zeros((nx, nx))
    P[:m, :m] = 2.0 * np.eye(m)
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = 1e-11
    solver = clarabel.DefaultSolver(sparse.triu(sparse.csc_matrix(P)).tocsc(), np.zeros(nx),
                                    Aall, b, [clarabel.ZeroConeT(eq.shape[0]),
                                              clarabel.NonnegativeConeT(len(b) - eq.shape[0])],
                                    settings)
    sol = solver.solve()
    if str(sol.status) != 'Solved':
        return None
    return np.array(sol.x[:m])


def coupled_lp(setup, maps, S, A, limits, load=None):
    """
    HiGHS: with ``load``, the largest alpha holding alpha * load; else min max |u_i|/limit_i.

    Returns the optimum (alpha or t) or None.
    """
    m = S.shape[1]
    eq, poly, b_poly = _rows(setup, maps, S, A)
    nx = eq.shape[1] + 1
    eq = np.hstack((eq, np.zeros((eq.shape[0], 1))))
    b_eq = np.zeros(eq.shape[0])
    c = np.zeros(nx)
    box = np.zeros((2 * m, nx))
    box[:m, :m], box[m:, :m] = np.eye(m), -np.eye(m)
    if load is not None:
        eq[:6, -1] = np.asarray(load, float)
        c[-1] = -1.0
        b_box = np.concatenate((limits, limits))
    else:
        b_eq[:6] = -setup.external_wrench
        c[-1] = 1.0
        box[:, -1] = -np.concatenate((limits, limits))
        b_box = np.zeros(2 * m)
    A_ub = np.vstack((np.hstack((poly, np.zeros((poly.shape[0], 1)))), box))
    res = linprog(c, A_ub=A_ub, b_ub=np.concatenate((b_poly, b_box)), A_eq=eq, b_eq=b_eq,
                  bounds=[(None, None)] * (nx - 1) + [(0, None)], method='highs')
    return float(res.x[-1]) if res.status == 0 else None
