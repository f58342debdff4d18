# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
QP backends for the tau-QP: ProxSuite (the default), DAQP and quadprog.

Every backend implements :class:`~grasp_torque_opt.backends.base.Backend` and is
registered by name in :mod:`~grasp_torque_opt.backends.registry`, with its own settings
type. Every backend takes a built :class:`~grasp_torque_opt.core.tau_qp.TauQP` and returns
a :class:`~grasp_torque_opt.core.solution.RawResult`; none is trusted: the caller
certifies whatever comes back (:func:`grasp_torque_opt.methods.dispatch.solve`). Each
refuses non-finite data and inverted bounds before calling its solver, and each
has its iterations capped, so one cycle can never stall.

- ``proxsuite``: :class:`~grasp_torque_opt.backends.proxsuite.TauQPSolver`, dense ProxQP,
  the design's choice.
- ``daqp``: DAQP, a dual active-set method, exact to its tolerances on small
  dense QPs. A positive semidefinite Hessian (the internal-force variables z
  carry no cost) is handled by DAQP's proximal-point iterations.
- ``quadprog``: Goldfarb-Idnani; needs a positive definite Hessian, so only
  grasps without internal-force variables (k = 0, e.g. the Allegro's four
  fingertips); otherwise it returns an error, never a regularized answer.
"""

from __future__ import annotations

import warnings

from grasp_torque_opt.backends.base import Backend
from grasp_torque_opt.backends.daqp import DaqpSettings, DaqpSolver
from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings, TauQPSolver
from grasp_torque_opt.backends.quadprog import QuadprogSettings, QuadprogSolver
from grasp_torque_opt.backends.registry import (
    as_backend,
    available,
    BACKENDS,
    is_backend,
    make_solver,
    REGISTRY,
    settings_for,
)

__all__ = ['as_backend', 'available', 'Backend', 'BACKENDS', 'DaqpSettings', 'DaqpSolver',
           'is_backend', 'make_solver', 'ProxSuiteSettings', 'QuadprogSettings', 'QuadprogSolver',
           'REGISTRY', 'settings_for', 'single_threaded_math', 'TauQPSolver']


def single_threaded_math() -> None:
    """
    Limit BLAS and OpenMP to one thread in this process (the node's and CLI's mains call it).

    The matrices of one grasp are tiny; with OpenBLAS's default threads, a
    triangular solve in the QP build took 8 to 16 ms instead of tens of
    microseconds whenever the other core was busy, and SLSQP 387 ms instead of
    8 ms. A library user running the cycle in a loop should do the same
    (``threadpoolctl.threadpool_limits(1)`` or ``OPENBLAS_NUM_THREADS=1``).
    """
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # optional: a ROS distribution may not have it
        warnings.warn('threadpoolctl is not installed: BLAS keeps its own thread count '
                      '(pip install threadpoolctl, or set OPENBLAS_NUM_THREADS=1)', stacklevel=2)
        return
    threadpool_limits(1)
