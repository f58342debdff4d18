# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Any URDF the solver accepts, made simulable: meshes found, the robot welded, couplings.

- Mesh paths (``package://NAME/...``, ``file://...``, relative) become absolute files:
  a package is looked up in example-robot-data's share folder (for
  ``example-robot-data``), then ``share/NAME`` under each ``AMENT_PREFIX_PATH`` entry,
  then ``NAME`` under each ``ROS_PACKAGE_PATH`` entry; a relative path is relative to
  the URDF's folder. A mesh not found is an error naming it.
- Every joint that neither is an actuator nor follows one is welded at its position in
  the grasp (the joint is removed and its body turned by it), so a hand inside a robot
  holds its pose: MuJoCo would otherwise start them at 0 and let them fall.
- Each coupled joint that follows an actuator becomes a MuJoCo joint equality
  (q_f = offset + multiplier q_t): MuJoCo's URDF import ignores mimic tags.
"""

from __future__ import annotations

import os
from pathlib import Path
import xml.etree.ElementTree as ET

from grasp_torque_opt.core.exceptions import cut, InputError
from grasp_torque_opt.core.hand import example_robot_data_dir, Hand
import mujoco
import numpy as np

PACKAGE = 'package://'


def package_roots(name: str) -> list[Path]:
    """Folders where ROS package ``name`` may be, in the order they are tried."""
    roots = []
    if name == 'example-robot-data':
        try:
            roots.append(example_robot_data_dir().parent)
        except InputError:
            pass
    for prefix in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep):
        if prefix:
            roots.append(Path(prefix) / 'share' / name)
    for folder in os.environ.get('ROS_PACKAGE_PATH', '').split(os.pathsep):
        if folder:
            roots.append(Path(folder) / name)
    return roots


def resolve_mesh(filename: str, urdf_dir: Path | None) -> Path:
    """
    Return the file a URDF mesh ``filename`` names.

    Raises:
        InputError: not found (field ``hand.urdf``), naming the mesh and where it looked.
    """
    if filename.startswith(PACKAGE):
        name, _, rest = filename[len(PACKAGE):].partition('/')
        roots = package_roots(name)
        for root in roots:
            if (root / rest).is_file():
                return root / rest
        raise InputError('hand.urdf', f"mesh '{cut(filename)}': package '{cut(name)}' not "
                         f'found (looked in {len(roots)} folders: example-robot-data, '
                         'AMENT_PREFIX_PATH, ROS_PACKAGE_PATH)')
    path = Path(filename[len('file://'):] if filename.startswith('file://') else filename)
    if not path.is_absolute() and urdf_dir is not None:
        path = urdf_dir / path
    if not path.is_file():
        raise InputError('hand.urdf', f"mesh '{cut(filename)}' not found")
    return path


def resolve_meshes(root: ET.Element, urdf_dir: Path | None) -> None:
    """Make every collision mesh's filename an absolute path (in place)."""
    for mesh in root.iter('mesh'):
        if mesh.get('filename'):
            mesh.set('filename', str(resolve_mesh(mesh.get('filename'), urdf_dir)))


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
