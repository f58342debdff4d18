# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The backend protocol: what every QP backend of the tau-QP is and does.

A backend is a class registered in :mod:`grasp_torque_opt.backends.registry` with its
own frozen settings dataclass. The dispatcher
(:func:`grasp_torque_opt.methods.dispatch.solve`) and the node's cycle
(:mod:`grasp_torque_opt.control`) call only what :class:`Backend` names.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

from grasp_torque_opt.core.solution import RawResult
from grasp_torque_opt.core.tau_qp import TauQP


@runtime_checkable
class Backend(Protocol):
    """
    A tau-QP solver: a built :class:`~grasp_torque_opt.core.tau_qp.TauQP` in, a RawResult out.

    Attributes:
        name: the backend's name, one of :data:`~grasp_torque_opt.backends.BACKENDS`
            (``Solution.backend`` reports it).
        settings: the backend's own frozen settings dataclass (e.g.
            :class:`~grasp_torque_opt.backends.proxsuite.ProxSuiteSettings`).
        warm_start: whether a solve starts from the previous one (False for a
            backend without warm starts).
        last_warm: whether the last answer came from a warm start (not redone
            cold): the caller redoes such an answer cold when its certificate fails.
    """

    name: str
    settings: object
    warm_start: bool
    last_warm: bool

    def solve(self, qp: TauQP, cold: bool = False, deadline: float | None = None
              ) -> RawResult:
        """
        Solve a built tau-QP; nothing is trusted, the caller certifies the answer.

        A backend refuses bad data (:func:`~grasp_torque_opt.core.tau_qp.check_data`)
        with an error result and caps its iterations, so no call stalls.

        Args:
            qp: the QP.
            cold: start cold even with ``warm_start`` (the caller's redo of a warm
                answer that failed its certificate).
            deadline: ``time.perf_counter()`` value by which to stop [s] (None: only
                the iteration caps).

        Returns:
            The raw result (x = [tau; z] when there is one).

        Raises:
            SolverError: the solver itself raised (chained).
        """
        ...
