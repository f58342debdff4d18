"""The certificate every result must pass before anyone sees it.

Checks the recomputed contact wrenches f against the exact problem, not the
solver's view of it: equilibrium G f + w_ext = 0, tau = J^T f, the exact
(nonlinear) soft-finger cone, the minimum normal force, and the torque limits.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from grasp_torque_opt.friction import cone_margin
from grasp_torque_opt.scenario import Friction

DEFAULT_TOLERANCE = 1e-6


@dataclass(frozen=True)
class Certificate:
    """Residuals of a candidate solution; all are >= 0 and 0 is exact.

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
        """True when the solution is finite and every residual is within tolerance."""
        return self.finite and self.worst <= self.tolerance

    @property
    def worst(self) -> float:
        """The largest residual."""
        return max(self.equilibrium, self.torque, self.cone, self.normal_force,
                   self.torque_limit)

    def as_dict(self) -> dict:
        """Plain-data form (JSON), with ``ok``."""
        return {**asdict(self), "ok": self.ok}


def certify(G: np.ndarray, J: np.ndarray, external_wrench: np.ndarray, friction: Friction,
            tau_min: np.ndarray, tau_max: np.ndarray, tau: np.ndarray, f: np.ndarray,
            tolerance: float = DEFAULT_TOLERANCE) -> Certificate:
    """Check a candidate (tau, f) against the exact problem.

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
    finite = bool(np.all(np.isfinite(tau)) and np.all(np.isfinite(f)))
    if not finite:
        inf = float("inf")
        return Certificate(inf, inf, inf, inf, inf, False, tolerance)
    wrenches = f.reshape(-1, 4)
    return Certificate(
        equilibrium=float(np.max(np.abs(G @ f + external_wrench))),
        torque=float(np.max(np.abs(J.T @ f - tau))),
        cone=float(max(0.0, -np.min(cone_margin(wrenches, friction.mu1, friction.mu2)))),
        normal_force=float(max(0.0, np.max(friction.min_normal_force - wrenches[:, 2]))),
        torque_limit=float(max(0.0, np.max(tau_min - tau), np.max(tau - tau_max))),
        finite=True,
        tolerance=tolerance,
    )
