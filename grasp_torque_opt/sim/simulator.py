# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
A hand holding an object in MuJoCo, driven as an effort controller drives a hand.

The joints get the commanded torque plus a joint impedance around a reference
configuration, as real hand drivers add (docs/simulation.md, "Impedance"):

    u = command + Kp (q_ref - q) - Kd qdot.

Kd is integrated implicitly (as MuJoCo joint damping): the URDF's link inertias
(down to 1e-6 kg m^2, no motor inertia) make an explicit damper at 1 kHz unstable
above about 0.02 N m s/rad. Before :meth:`HandSim.release` the object is pinned at
its pose, so that the fingers settle on it; ``q_ref`` is then the settled
configuration, so the impedance adds nothing while the grasp stays put.
"""

from __future__ import annotations

from dataclasses import dataclass

from grasp_torque_opt.sim.model import SimModel
import mujoco
import numpy as np


@dataclass(frozen=True)
class ContactReading:
    """
    What the simulation measures at one planned contact.

    Attributes:
        touching: the link touches the object.
        force: force of the link on the object, base axes [N], shape (3,).
        torque: moment of it about the contact point, base axes [N m], shape (3,).
        position: contact point, base frame [m], shape (3,) (NaN if not touching).
        normal: unit normal into the object, base axes, shape (3,) (NaN if not touching).
    """

    touching: bool
    force: np.ndarray
    torque: np.ndarray
    position: np.ndarray
    normal: np.ndarray


class HandSim:
    """Stepping, impedance, pinning and measurements of one :class:`SimModel`."""

    def __init__(self, sim: SimModel, q0: np.ndarray, kp: float = 1.0, kd: float = 0.01
                 ) -> None:
        """
        Start a simulation at ``q0``, the object pinned.

        Args:
            sim: the compiled model.
            q0: start configuration of the actuated joints [rad], shape (m,).
            kp: impedance stiffness [N m/rad], every joint.
            kd: impedance damping [N m s/rad], every joint.
        """
        if kp < 0 or kd < 0:
            raise ValueError(f'kp and kd must be >= 0, got {kp}, {kd}')
        self.sim = sim
        self.model = sim.model
        self.model.dof_damping[sim.dof_adr] += kd
        self.kp, self.kd = kp, kd
        self.data = mujoco.MjData(self.model)
        self.data.qpos[sim.qpos_adr] = q0
        self._follow()
        self.q_ref = np.array(q0, dtype=float)
        self.command = np.zeros(len(sim.joints))
        self._pose = self.data.qpos[sim.object_qpos:sim.object_qpos + 7].copy()
        self.pinned = True
        #: Keep the joints at q_ref (a driver in position mode, before effort commands).
        self.hold_joints = False
        self.release_pose = self._pose.copy()
        self.release_time: float | None = None
        mujoco.mj_forward(self.model, self.data)

    @property
    def time(self) -> float:
        """Return the simulated time [s]."""
        return float(self.data.time)

    @property
    def q(self) -> np.ndarray:
        """Actuated joint positions [rad]."""
        return self.data.qpos[self.sim.qpos_adr].copy()

    @property
    def qdot(self) -> np.ndarray:
        """Actuated joint velocities [rad/s]."""
        return self.data.qvel[self.sim.dof_adr].copy()

    def effort(self) -> np.ndarray:
        """Joint torques the actuators apply, impedance included [N m]."""
        return self.command + self.kp * (self.q_ref - self.q) - self.kd * self.qdot

    def remove_object(self, away: float = 1.0) -> None:
        """
        Take the object out of the hand: pinned ``away`` metres below the base, out of reach.

        The hand then holds nothing (finger gravity compensation, the node's
        ``hold_object`` false); :meth:`release` is not called.
        """
        self._pose[:3] = self._pose[:3] - np.array([0.0, 0.0, away])
        self.pinned = True
        self._constrain()
        mujoco.mj_forward(self.model, self.data)

    def release(self) -> None:
        """Let the object go; the impedance now holds the settled configuration."""
        self.pinned = False
        self.q_ref = self.q
        self.release_pose = self.data.qpos[self.sim.object_qpos:
                                           self.sim.object_qpos + 7].copy()
        self.release_time = self.time

    def step(self, n: int = 1) -> None:
        """Advance n steps with the current command held."""
        d, s = self.data, self.sim
        for _ in range(n):
            d.qfrc_applied[s.dof_adr] = self.command + self.kp * (self.q_ref - d.qpos[s.qpos_adr])
            self._constrain()
            mujoco.mj_step(self.model, d)
        if self.pinned or self.hold_joints:  # readings see the held state, not one step off
            self._constrain()
            mujoco.mj_forward(self.model, d)

    def _constrain(self) -> None:
        d, s = self.data, self.sim
        if self.pinned:
            d.qpos[s.object_qpos:s.object_qpos + 7] = self._pose
            d.qvel[s.object_dof:s.object_dof + 6] = 0.0
        if self.hold_joints:
            d.qpos[s.qpos_adr] = self.q_ref
            d.qvel[s.dof_adr] = 0.0
            self._follow()

    def _follow(self) -> None:
        """Put the coupled joints where their couplings say (their equalities hold them)."""
        for follower, target, k, b in self.sim.followers:
            self.data.qpos[follower] = k * self.data.qpos[target] + b

    def object_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """Object position [m] and quaternion [w, x, y, z], base frame."""
        p = self.data.qpos[self.sim.object_qpos:self.sim.object_qpos + 7]
        return p[:3].copy(), p[3:].copy()

    def motion(self) -> tuple[float, float]:
        """Drift [m] and rotation [rad] of the object since release (or start)."""
        pos, quat = self.object_pose()
        drift = float(np.linalg.norm(pos - self.release_pose[:3]))
        dot = min(1.0, abs(float(quat @ self.release_pose[3:])))
        return drift, 2.0 * float(np.arccos(dot))

    def touch(self) -> np.ndarray:
        """
        Return each planned contact's link's touch sensor reading [N], shape (p,).

        The summed normal force of the link's contacts, as a fingertip's tactile sensor
        reads it (a model built with ``SimSettings.touch``; else empty).
        """
        return self.data.sensordata[list(self.sim.touch_adr)].copy()

    def readings(self) -> tuple[list[ContactReading], float]:
        """
        Read what touches the object at each planned contact, and the unplanned contacts' force.

        The latter is the force of every other hand body on the object [N].
        """
        m, d, s = self.model, self.data, self.sim
        per = {b: [] for b in s.contact_bodies}
        other = np.zeros(3)
        f6 = np.zeros(6)
        for i in range(d.ncon):
            c = d.contact[i]
            b1, b2 = m.geom_bodyid[c.geom1], m.geom_bodyid[c.geom2]
            if s.object_body not in (b1, b2):
                continue
            mujoco.mj_contactForce(m, d, i, f6)
            frame = c.frame.reshape(3, 3)  # rows: normal (geom1 to geom2), tangents
            sign = 1.0 if b2 == s.object_body else -1.0  # f6 acts on geom2
            hand_body = b1 if b2 == s.object_body else b2
            force, torque = sign * frame.T @ f6[:3], sign * frame.T @ f6[3:]
            if hand_body in per:
                per[hand_body].append((force, torque, c.pos.copy(), sign * frame[0]))
            else:
                other += force
        out = []
        nan = np.full(3, np.nan)
        for body in s.contact_bodies:
            hits = per[body]
            if not hits:
                out.append(ContactReading(False, np.zeros(3), np.zeros(3), nan, nan))
                continue
            force = sum(h[0] for h in hits)
            torque = sum(h[1] for h in hits)
            position = np.mean([h[2] for h in hits], axis=0)
            normal = sum(h[3] for h in hits)
            out.append(ContactReading(True, force, torque, position,
                                      normal / np.linalg.norm(normal)))
        return out, float(np.linalg.norm(other))


def wrench_in_frame(reading: ContactReading, rotation: np.ndarray) -> np.ndarray:
    """Express a reading as [fx, fy, fz, mz] in a contact frame (columns x, y, z in base axes)."""
    f = rotation.T @ reading.force
    return np.array([f[0], f[1], f[2], float(rotation[:, 2] @ reading.torque)])


def friction_usage(wrench: np.ndarray, mu1: float, mu2: float) -> float:
    """
    Return the share of the exact soft-finger cone a wrench uses [-].

    The share is (||f_t||/mu1 + |mz|/mu2) / fz: 1 on the cone, inf when not pressing.
    """
    if wrench[2] <= 0.0:
        return float('inf')
    return float((np.hypot(wrench[0], wrench[1]) / mu1 + abs(wrench[3]) / mu2) / wrench[2])
