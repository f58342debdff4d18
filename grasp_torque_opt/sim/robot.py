# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Any URDF the solver accepts, made simulable: meshes found, the robot welded, couplings.

- Mesh paths (``package://NAME/...``, ``file://...``, relative) become absolute files
  (:mod:`grasp_torque_opt.core.meshes`, shared with the collision model); a mesh not
  found is an error naming it.
- Every joint that neither is an actuator nor follows one is welded at its position in
  the grasp (the joint is removed and its body turned by it), so a hand inside a robot
  holds its pose: MuJoCo would otherwise start them at 0 and let them fall.
- Each coupled joint that follows an actuator becomes a MuJoCo joint equality
  (q_f = offset + multiplier q_t): MuJoCo's URDF import ignores mimic tags.
"""

from __future__ import annotations

from grasp_torque_opt.core.hand import Hand
import mujoco
import numpy as np


def _kept(hand: Hand) -> set[str]:
    """Return the joints that move in the simulation: actuators and their followers."""
    actuators = set(hand.joints)
    return actuators | {m.joint for m in hand.coupling.mimics
                        if hand.coupling.root(m.joint) in actuators}


def weld_and_couple(spec: mujoco.MjSpec, hand: Hand, q: np.ndarray) -> list:
    """
    Weld the joints that do not move at their positions in q, and couple the followers.

    Args:
        spec: the MuJoCo spec of the URDF (not compiled yet).
        hand: the hand (actuators and coupling).
        q: the grasp's full configuration (Pinocchio's order).

    Returns:
        The kept followers' relations (:class:`grasp_torque_opt.core.coupling.Mimic`).
        MuJoCo's joint equality holds q_f - q_f0 = b + k (q_t - q_t0) with q0 MuJoCo's
        reference positions, 0 for URDF joints: q_f = b + k q_t.
    """
    model = hand.model
    kept = _kept(hand)
    position = {model.names[j]: float(q[model.joints[j].idx_q])
                for j in range(1, model.njoints) if model.joints[j].nq == 1}
    for joint in list(spec.joints):
        if joint.type not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            continue
        if joint.name in kept:
            continue
        _weld(joint, position.get(joint.name, 0.0))
        spec.delete(joint)
    coupled = []
    for m in hand.coupling.mimics:
        if m.joint in kept:
            spec.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, name1=m.joint, name2=m.target,
                              objtype=mujoco.mjtObj.mjOBJ_JOINT,
                              data=[m.offset, m.multiplier] + [0.0] * 10,
                              solref=[0.002, 1.0])
            coupled.append(m)
    return coupled


def _weld(joint, value: float) -> None:
    """Turn (or shift) the joint's body by ``value`` about its axis, in the parent frame."""
    body = joint.parent
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, np.asarray(body.quat, dtype=float))
    R = R.reshape(3, 3)
    axis = np.asarray(joint.axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    p = np.asarray(joint.pos, dtype=float)
    if joint.type == mujoco.mjtJoint.mjJNT_SLIDE:
        body.pos = list(np.asarray(body.pos, dtype=float) + R @ (axis * value))
        return
    turn = np.zeros(4)
    mujoco.mju_axisAngle2Quat(turn, axis, value)
    Rj = np.zeros(9)
    mujoco.mju_quat2Mat(Rj, turn)
    # x_parent = pos + R (p + Rj (x - p)): the body frame moves to pos + R (p - Rj p).
    body.pos = list(np.asarray(body.pos, dtype=float) + R @ (p - Rj.reshape(3, 3) @ p))
    quat = np.zeros(4)
    mujoco.mju_mulQuat(quat, np.asarray(body.quat, dtype=float), turn)
    body.quat = list(quat)
