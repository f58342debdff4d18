# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
quadprog (Goldfarb-Idnani) on the tau-QP.

It needs a positive definite Hessian, so only grasps without internal-force
variables (k = 0, e.g. the Allegro's four fingertips); otherwise it returns an
error, never a regularized answer.
"""

from __future__ import annotations

from dataclasses import dataclass
import time

from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings
from grasp_torque_opt.core.solution import RawResult
from grasp_torque_opt.core.tau_qp import check_data, TauQP
import numpy as np


@dataclass(frozen=True)
class QuadprogSettings:
    """
    quadprog's settings: none (no tolerances; its active set ends after finitely many steps).

    A type of its own all the same, as every backend has (the registry maps a
    :class:`~grasp_torque_opt.backends.proxsuite.ProxSuiteSettings` to it).
    """

    @classmethod
    def from_proxsuite(cls, settings: ProxSuiteSettings) -> QuadprogSettings:
        """Return quadprog's settings for a ProxSuiteSettings: nothing of it applies."""
        return cls()


class QuadprogSolver:
    """
    quadprog (Goldfarb-Idnani) on the tau-QP; grasps with k = 0 only.

    It has no warm start (``warm_start`` and ``last_warm`` are always False).

    Args:
        settings: its settings (there are none to set).
    """

    name = 'quadprog'
    warm_start = False
    last_warm = False

    def __init__(self, settings: QuadprogSettings | None = None) -> None:
        import quadprog

        self._quadprog = quadprog
        self.settings = settings or QuadprogSettings()

    def solve(self, qp: TauQP, cold: bool = False, deadline: float | None = None
              ) -> RawResult:
        """
        Solve a built tau-QP; none starts past ``deadline``.

        Args:
            qp: the QP.
            cold: every quadprog solve is cold (no warm start to skip).
            deadline: ``time.perf_counter()`` value [s]; a quadprog solve ends after
                finitely many active-set steps.
        """
        if deadline is not None and time.perf_counter() >= deadline:
            return RawResult('error', None, 0, 0.0, 'time budget spent before quadprog started')
        why = check_data(qp)
        if why:
            return RawResult('error', None, 0, 0.0, why)
        if qp.H.shape[0] != qp.m:
            return RawResult('error', None, 0, 0.0, 'quadprog needs a positive definite '
                             f'Hessian; this grasp has {qp.H.shape[0] - qp.m} internal-force '
                             'variables')
        n = qp.m
        lo, hi = np.isfinite(qp.l_box), np.isfinite(qp.u_box)
        eye = np.eye(n)
        # quadprog: C^T x >= b, the first meq rows equalities.
        C = np.vstack((qp.A, -qp.C, eye[lo], -eye[hi])).T
        b = np.concatenate((qp.b, -qp.u, qp.l_box[lo], -qp.u_box[hi]))
        t0 = time.perf_counter()
        try:
            x, _, _, _, iterations, _ = self._quadprog.solve_qp(qp.H.copy(), -qp.g, C, b,
                                                                meq=qp.A.shape[0])
        except ValueError as e:
            elapsed = time.perf_counter() - t0
            status = 'infeasible' if 'inconsistent' in str(e) else 'error'
            return RawResult(status, None, 0, elapsed, f'quadprog: {e}')
        elapsed = time.perf_counter() - t0
        return RawResult('solved', np.asarray(x, dtype=float), int(iterations[0]), elapsed,
                         'quadprog solved')
