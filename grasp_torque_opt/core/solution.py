# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The result type shared by every method."""

from __future__ import annotations

from dataclasses import dataclass, field

from grasp_torque_opt.core.bounds import Bounds
from grasp_torque_opt.core.certificate import Certificate
import numpy as np

OPTIMAL = 'optimal'
INFEASIBLE = 'infeasible'
FAILED = 'failed'


@dataclass
class Solution:
    """
    Outcome of one method on one grasp.

    ``status`` is ``optimal`` only when the certificate passed; ``infeasible``
    only when no torque can hold the load (confirmed independently for the
    linearized methods); ``failed`` when the solver gave nothing certifiable.
    ``tau`` and ``wrenches`` are None unless the status is ``optimal``.

    Attributes:
        status: ``optimal``, ``infeasible`` or ``failed``.
        method: ``tau-qp``, ``tau-qp-adaptive``, ``force-qp``, ``socp`` or ``nlp``.
        joints: actuated joints, the order of tau.
        tau: joint torques [N m], shape (m,).
        wrenches: contact wrenches [fx, fy, fz, mz] in contact frames, shape (p, 4).
        iterations: solver iterations.
        solve_time_s: time in the solver call [s].
        certificate: residuals of the candidate (None if the solver gave none).
        message: what happened, in words.
        timings: seconds per stage (``maps``, ``build``, ``solve``, ``certify``).
        backend: who solved: the QP backend for ``tau-qp`` (the fallback's name
            when the first backend failed), else the method.
        bounds: for ``tau-qp-adaptive``, the certified bounds on the exact-cone
            optimum and the gap (None for the other methods).
        objective: ``sum-of-squares`` or ``min-max`` (docs/planner.md).
        friction_margin: the margin k planned with [-] (cone of mu/(1+k)).
        friction_usage: per contact (||f_t||/mu1 + |m_z|/mu2)/f_z on the unreduced
            cone, shape (p,) [-]; None unless optimal.
        max_torque_ratio: max_i |tau_i + offset_i| / limit_i [-]; None unless optimal.
        infeasibility: why infeasible (:mod:`grasp_torque_opt.methods.explain`,
            plain data) when it was asked for, else None.
    """

    status: str
    method: str
    joints: list[str]
    tau: np.ndarray | None = None
    wrenches: np.ndarray | None = None
    iterations: int = 0
    solve_time_s: float = 0.0
    certificate: Certificate | None = None
    message: str = ''
    timings: dict[str, float] = field(default_factory=dict)
    backend: str = ''
    bounds: Bounds | None = None
    objective: str = 'sum-of-squares'
    friction_margin: float = 0.0
    friction_usage: np.ndarray | None = None
    max_torque_ratio: float | None = None
    infeasibility: dict | None = None

    @property
    def optimal(self) -> bool:
        """Return True for a certified optimum."""
        return self.status == OPTIMAL

    @property
    def torque_norm(self) -> float | None:
        """||tau||_2 [N m], or None."""
        return None if self.tau is None else float(np.linalg.norm(self.tau))


@dataclass(frozen=True)
class RawResult:
    """
    What a solver said, before certification.

    Attributes:
        status: ``solved``, ``infeasible`` or ``error``.
        x: the solver's primal variables (None if it gave none).
        iterations: iterations it reported.
        solve_time_s: wall time of the solver call [s].
        message: the solver's own status text.
    """

    status: str
    x: np.ndarray | None
    iterations: int
    solve_time_s: float
    message: str
