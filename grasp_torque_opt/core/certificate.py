# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The certificate every result must pass before anyone sees it.

Checks the recomputed contact wrenches f against the exact problem, not the
solver's view of it: equilibrium G f + w_ext = 0, tau = J^T f, the exact
(nonlinear) soft-finger cone, the minimum normal force, and the torque limits.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
import math

from grasp_torque_opt.core.friction import cone_margin
from grasp_torque_opt.core.scenario import Friction
import numpy as np

DEFAULT_TOLERANCE = 1e-6


@dataclass(frozen=True)
class Certificate:
    """
    Residuals of a candidate solution; all are >= 0 and 0 is exact.

    Attributes:
        equilibrium: ||G f + w_ext||_inf [N, N m].
        torque: ||J^T f - tau||_inf [N m].
        cone: largest exact-cone violation, max(0, -margin) [N].
        normal_force: largest shortfall below the minimum normal force [N].
        torque_limit: largest excess of tau_i beyond its bounds [N m].
        finite: every entry of tau and f is finite.
        tolerance: bound that every residual must meet.
    """

    equilibrium: float
    torque: float
    cone: float
    normal_force: float
    torque_limit: float
    finite: bool
    tolerance: float

    @property
    def ok(self) -> bool:
        """Return True when the solution is finite and every residual is within tolerance."""
        return self.finite and self.worst <= self.tolerance

    @property
    def worst(self) -> float:
        """Return the largest residual."""
        return max(self.equilibrium, self.torque, self.cone, self.normal_force,
                   self.torque_limit)

    def as_dict(self) -> dict:
        """Plain-data form (JSON), with ``ok``."""
        return {**asdict(self), 'ok': self.ok}


def certify(G: np.ndarray, J: np.ndarray, external_wrench: np.ndarray, friction: Friction,
            tau_min: np.ndarray, tau_max: np.ndarray, tau: np.ndarray, f: np.ndarray,
            tolerance: float = DEFAULT_TOLERANCE) -> Certificate:
    """
    Check a candidate (tau, f) against the exact problem.

    Args:
        G: grasp matrix, shape (6, 4p).
        J: hand Jacobian, shape (4p, m).
        external_wrench: w_ext, shape (6,) [N, N m].
        friction: friction model (exact cone, minimum normal force).
        tau_min: lower torque bound, shape (m,) [N m].
        tau_max: upper torque bound, shape (m,) [N m].
        tau: joint torques, shape (m,) [N m].
        f: stacked contact wrenches, shape (4p,), contact frames.
        tolerance: bound on every residual, in SI units.
    """
    tau = np.asarray(tau, dtype=float)
    f = np.asarray(f, dtype=float)
    # One sum per array: NaN or Inf anywhere makes it non-finite.
    if not math.isfinite(tau.sum() + f.sum()):
        inf = float('inf')
        return Certificate(inf, inf, inf, inf, inf, False, tolerance)
    w = f.reshape(-1, 4)
    margin = cone_margin(w, friction.mu1, friction.mu2)
    over = np.concatenate((tau_min - tau, tau - tau_max))
    return Certificate(
        equilibrium=float(np.abs(G @ f + external_wrench).max()),
        torque=float(np.abs(J.T @ f - tau).max()),
        cone=max(0.0, -float(margin.min())),
        normal_force=max(0.0, friction.min_normal_force - float(w[:, 2].min())),
        torque_limit=max(0.0, float(over.max())),
        finite=True,
        tolerance=tolerance,
    )
