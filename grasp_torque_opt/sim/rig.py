# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The simulated hand as a test rig: a moving base, encoder noise, and the torques it applies.

:class:`RigSim` is a :class:`~grasp_torque_opt.sim.simulator.HandSim` that

- moves its base by :class:`~grasp_torque_opt.sim.base_motion.BaseMotion` (the
  apparent gravity, set before every step);
- reads its joints through a noisy encoder: each step draws one reading, q plus
  white Gaussian noise, which the impedance uses and the driver publishes (noise on
  the node's input and in the driver's loop, as an encoder's noise is);
- records the torque it applied in the last step: command plus Kp (q_ref - reading),
  and the damping -Kd qdot that MuJoCo integrates implicitly (at the velocity the
  step ends with), so that :meth:`RigSim.effort` is what the joints got;
- keeps the mean effort since release: the RMS of the applied joint torques over
  every step and joint [N m];
- pushes the object, once released, with a constant force at its centre
  (:attr:`RigSim.object_force`, base axes [N]): the grasp benchmarks' disturbance;
- reports in its joint states' effort (:meth:`RigSim.reported_effort`) either the
  torque it applied (``effort_report`` ``applied``, a driver with current sensing) or the
  controller's last command (``commanded``, as the Allegro V5's driver does): the
  impedance around ``q_ref`` (the grasp configuration while the object is pinned, the
  settled configuration from release on) is then not in it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.sim.base_motion import BaseMotion, imu_reading
from grasp_torque_opt.sim.model import SimModel
from grasp_torque_opt.sim.simulator import HandSim
import mujoco
import numpy as np

#: What a driver's joint states' effort may be: the torque applied, or the command.
EFFORT_REPORTS = ('applied', 'commanded')


@dataclass(frozen=True)
class Disturbances:
    """
    What the rig does to the hand that the node is not told.

    Attributes:
        motion: the base's acceleration (apparent gravity).
        joint_noise: standard deviation of the encoder noise [rad].
        seed: seed of the noise.
    """

    motion: BaseMotion = field(default_factory=BaseMotion)
    joint_noise: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        """Refuse a negative or non-finite noise."""
        if not (np.isfinite(self.joint_noise) and self.joint_noise >= 0):
            raise ValueError(f'joint_noise must be finite and >= 0, got {self.joint_noise}')


class RigSim(HandSim):
    """A :class:`HandSim` on a moving base with noisy encoders, reporting what it applies."""

    def __init__(self, sim: SimModel, q0: np.ndarray, kp: float = 1.0, kd: float = 0.01,
                 disturbances: Disturbances = Disturbances(), base_frame: str | None = None
                 ) -> None:
        """
        Start the rig at ``q0``, the object pinned.

        Args:
            sim: the compiled model.
            q0: start configuration of the actuated joints [rad], shape (m,).
            kp: impedance stiffness [N m/rad].
            kd: impedance damping [N m s/rad].
            disturbances: base motion and encoder noise.
            base_frame: the body the IMU is on and whose axes the base motion is
                given in (the hand's base frame); None: MuJoCo's world.

        Raises:
            InputError: ``base_frame`` is not a body of the model.
        """
        super().__init__(sim, q0, kp, kd)
        self.disturbances = disturbances
        self.base_body = 0
        if base_frame is not None:
            self.base_body = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, base_frame)
            if self.base_body < 0:
                raise InputError('hand.base_frame', f"'{base_frame}' is not a body of the "
                                 'MuJoCo model (the IMU sits on it)')
        self._gravity = self.model.opt.gravity.copy()  # MuJoCo's world axes
        self._rng = np.random.default_rng(disturbances.seed)
        self.reading = self.q
        self.applied = self.command + kp * (self.q_ref - self.reading)
        self._square_sum, self._count = 0.0, 0
        #: Force on the object's centre after release, base axes [N].
        self.object_force = np.zeros(3)
        #: The driver model that makes the joint torque from its last command at each
        #: step's reading (:mod:`~grasp_torque_opt.sim.drivers`); None: ``command`` is the
        #: torque (an effort controller).
        self.driver = None
        #: What the joint states' effort is: 'applied' or 'commanded' (EFFORT_REPORTS).
        self.effort_report = 'applied'

    def _encoder(self) -> np.ndarray:
        noise = self.disturbances.joint_noise
        q = self.data.qpos[self.sim.qpos_adr]
        return q + self._rng.normal(0.0, noise, q.shape) if noise > 0 else q.copy()

    def _apparent_gravity(self) -> None:
        t = -1.0 if self.release_time is None else self.time - self.release_time
        R = self.data.xmat[self.base_body].reshape(3, 3)  # base axes in world axes
        self.model.opt.gravity[:] = self._gravity - R @ self.disturbances.motion.acceleration(t)

    def step(self, n: int = 1) -> None:
        """Advance n steps: apparent gravity, one encoder reading and the command each."""
        command = self.command
        try:
            for _ in range(n):
                self._apparent_gravity()
                self.reading = self._encoder()
                if self.driver is not None:
                    command = self.driver.torque(self.reading)
                # Kp (q_ref - reading) = Kp (q_ref - q) - Kp noise: the noise goes in the command.
                self.command = command - self.kp * (self.reading - self.q)
                applied = command + self.kp * (self.q_ref - self.reading)
                if self.release_time is not None:
                    self.data.xfrc_applied[self.sim.object_body, :3] = (
                        self.sim.base_rotation @ self.object_force)
                super().step(1)
                self.applied = applied - self.kd * self.qdot
                if self.release_time is not None:
                    self._square_sum += float(self.applied @ self.applied)
                    self._count += self.applied.size
        finally:
            self.command = command

    def effort(self) -> np.ndarray:
        """Joint torques applied in the last step, impedance and damping included [N m]."""
        return self.applied.copy()

    def reported_effort(self) -> np.ndarray:
        """
        Return what the driver publishes as effort [N m]: :meth:`effort` or the command.

        ``commanded``: the controller's last command as it was sent (the encoder noise
        that the rig's impedance adds to it is not in it).
        """
        if self.effort_report == 'commanded':
            return np.array(self.command, dtype=float)
        return self.effort()

    def mean_effort(self) -> float:
        """RMS of the applied joint torques since release, over steps and joints [N m]."""
        return float(np.sqrt(self._square_sum / self._count)) if self._count else 0.0

    def imu(self) -> tuple[np.ndarray, np.ndarray]:
        """Specific force [m/s^2] and angular velocity [rad/s] at the base, base axes."""
        return imu_reading(self.model, self.data, self.base_body)
