# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Clarabel, the interior-point conic solver behind the reference methods."""

from __future__ import annotations

import time

import clarabel
from grasp_torque_opt.core.exceptions import SolverError
from grasp_torque_opt.core.solution import RawResult
import numpy as np
import scipy.sparse as sp

#: Clarabel's feasibility and gap tolerances (tighter than its defaults, so that
#: its optima pass the 1e-6 certificate with room to spare).
TOLERANCE = 1e-10


def solve_conic(P: np.ndarray, q: np.ndarray, A: np.ndarray, b: np.ndarray,
                cones: list) -> RawResult:
    """
    Minimize 1/2 x^T P x + q^T x subject to A x + s = b, s in the given cones.

    Args:
        P: PSD Hessian, shape (n, n) (its upper triangle is used).
        q: linear term, shape (n,).
        A: constraint matrix, rows in the order of ``cones``.
        b: right-hand side.
        cones: Clarabel cones (ZeroConeT, NonnegativeConeT, SecondOrderConeT).

    Raises:
        SolverError: Clarabel raised (chained).
    """
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = TOLERANCE
    settings.tol_feas = TOLERANCE
    settings.max_iter = 200
    t0 = time.perf_counter()
    try:
        solver = clarabel.DefaultSolver(sp.triu(sp.csc_matrix(P)).tocsc(), q,
                                        sp.csc_matrix(A), b, cones, settings)
        sol = solver.solve()
    except (KeyboardInterrupt, SystemExit):
        raise
    except BaseException as e:  # noqa: B036 -- a Rust panic arrives as pyo3's PanicException
        raise SolverError(f'Clarabel failed: {e}') from e
    elapsed = time.perf_counter() - t0
    name = str(sol.status)
    status = ('solved' if name in ('Solved', 'AlmostSolved')
              else 'infeasible' if name == 'PrimalInfeasible' else 'error')
    return RawResult(status, np.array(sol.x), int(sol.iterations), elapsed, name)
