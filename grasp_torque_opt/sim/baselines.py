# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Two controllers hands ship with, as baselines for the node on the same rig.

- :class:`Preset` (``--controller preset``): a grasp preset, as hand drivers offer
  (Allegro's grasp presets): fixed joint torques of one scalar effort level that
  close the fingers along the grasp's normals, tau = f J^T (lambda n) (contact i
  pressed with the normal force f lambda_i [N], the Jacobians at the grasp
  configuration; lambda from :func:`squeeze_pattern`, at least 1 each), plus
  the fingers' gravity g(q) for the scenario's gravity, clipped to the torque limits.
  :func:`tune_preset` chooses f once, on the nominal load (docs/simulation.md).
- :class:`Squeeze` (``--controller impedance``): position control, as grasp
  benchmarks drive a hand: the driver's impedance pulls the joints to the grasp
  pose commanded ``depth`` inside the object (each contact point moved that far
  along its inward normal, least-squares joint offsets), plus g(q); the squeeze
  comes from the joint stiffness Kp alone.

Neither knows the load. Both are asked with the encoder's reading, as the node is.
"""

from __future__ import annotations

from dataclasses import dataclass

from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.scenario import Scenario
from grasp_torque_opt.sim.episode import EpisodeSettings, run_episode, simulated
from grasp_torque_opt.sim.hold import gravity_torque
import numpy as np
from scipy.optimize import lsq_linear

#: Levels tried when tuning, the normal force per contact [N] (steps of sqrt 2).
PRESET_LEVELS = tuple(0.25 * np.sqrt(2) ** k for k in range(14))
#: How far inside the object the position-controlled squeeze commands the contacts [m].
SQUEEZE_DEPTH = 5e-3


class _GravityCompensated:
    """g(q) of the fingers for the scenario's gravity, at an encoder reading."""

    def __init__(self, setup: GraspSetup, gravity: np.ndarray) -> None:
        self.setup, self.gravity = setup, np.asarray(gravity, dtype=float)
        self._q = setup.q.copy()
        limits = setup.hand.torque_limits
        self.limits = np.full(len(setup.hand.joints), np.inf) if limits is None else limits

    def g(self, reading: np.ndarray) -> np.ndarray:
        self._q[self.setup.hand.idx_q] = reading
        return gravity_torque(self.setup, self._q, self.gravity)

    def clip(self, tau: np.ndarray) -> np.ndarray:
        return np.clip(tau, -self.limits, self.limits)


def squeeze_pattern(setup: GraspSetup) -> np.ndarray:
    """
    Return the preset's normal forces per unit level, shape (p,) [-].

    The normal forces along the grasp's normals whose net force on the object is
    smallest (least squares), every contact pressed with at least 1: a squeeze that
    pushes the object as little as normals alone can, whatever the load.
    """
    maps = setup.maps()
    p = len(setup.contacts)
    net = maps.G[:3, [4 * i + 2 for i in range(p)]]  # base axes, per unit normal force
    return lsq_linear(net, np.zeros(3), bounds=(1.0, np.inf)).x


class Preset(_GravityCompensated):
    """Fixed closing torques of one level along the grasp's normals, plus g(q)."""

    def __init__(self, setup: GraspSetup, gravity: np.ndarray, level: float) -> None:
        """
        Make the preset.

        Args:
            setup: the grasp (its contacts and configuration give the normals).
            gravity: gravity for g(q), base frame [m/s^2].
            level: the smallest normal force a contact is pressed with [N].
        """
        super().__init__(setup, gravity)
        if not (np.isfinite(level) and level >= 0):
            raise ValueError(f'level must be finite and >= 0 [N], got {level}')
        self.level = float(level)
        self.pattern = squeeze_pattern(setup)
        normal = np.zeros((len(self.pattern), 4))
        normal[:, 2] = self.pattern  # contact rows [x, y, z, mz], z the inward normal
        self.shape = setup.maps().J.T @ normal.ravel()

    def __call__(self, reading: np.ndarray) -> np.ndarray:
        """Return the command for an encoder reading [N m]."""
        return self.clip(self.level * self.shape + self.g(reading))


class Squeeze(_GravityCompensated):
    """Position control to the grasp pose commanded ``depth`` inside the object, plus g(q)."""

    def __init__(self, setup: GraspSetup, gravity: np.ndarray, depth: float = SQUEEZE_DEPTH
                 ) -> None:
        """
        Make the squeeze.

        Args:
            setup: the grasp.
            gravity: gravity for g(q), base frame [m/s^2].
            depth: how far inside the object each contact is commanded [m].
        """
        super().__init__(setup, gravity)
        if not (np.isfinite(depth) and depth >= 0):
            raise ValueError(f'depth must be finite and >= 0 [m], got {depth}')
        J = setup.maps().J
        p = len(setup.contacts)
        linear = J[[4 * i + k for i in range(p) for k in range(3)]]
        push = np.tile([0.0, 0.0, depth], p)
        self.depth = float(depth)
        self.target = setup.q[setup.hand.idx_q] + np.linalg.lstsq(linear, push, rcond=None)[0]

    def reference(self, settled: np.ndarray) -> np.ndarray:
        """Return the driver's reference: the target pose, wherever the fingers settled."""
        return self.target.copy()

    def __call__(self, reading: np.ndarray) -> np.ndarray:
        """Return the command for an encoder reading: g(q) [N m] (the driver squeezes)."""
        return self.clip(self.g(reading))


@dataclass(frozen=True)
class Tuning:
    """
    How the preset's level was chosen.

    Attributes:
        level: the level set [N].
        drift: the largest drift of the nominal load at that level [m].
        held: whether it held the nominal load within the drift limit.
    """

    level: float
    drift: float
    held: bool


def tune_preset(scenario: Scenario, kp: float, kd: float, duration: float = 1.0,
                rate: float = 250.0) -> Tuning:
    """
    Tune the preset once, on the nominal load, as a vendor would: the best level.

    Of :data:`PRESET_LEVELS`, the one whose episode (the scenario's object and
    gravity, no disturbance, the driver's Kp and Kd, ``duration`` after release)
    moves the object least. The level that holds with the least effort would be
    the lowest that holds; on the bundled grasp none holds within 1 mm (normal
    forces alone push the ball, docs/simulation.md), so the one knob is set where
    the ball moves least.
    """
    settings = EpisodeSettings(kp=kp, kd=kd, duration=duration, rate=rate)
    best = None
    for level in PRESET_LEVELS:
        setup, rig = simulated(scenario, settings)
        r = run_episode(rig, Preset(setup, scenario.gravity, level), settings)
        if best is None or r.max_drift < best.drift:
            best = Tuning(level=level, drift=r.max_drift, held=r.held)
    return best
