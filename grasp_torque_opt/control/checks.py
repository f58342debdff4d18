# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The input messages' checks on plain arrays (docs/node.md, "Input checks").

Each check is a pure function that returns the checked values or raises an
:class:`~grasp_torque_opt.core.exceptions.InputError` naming the field; the input
store (:mod:`grasp_torque_opt.control.inputs`) counts the rejection and keeps nothing.
"""

from __future__ import annotations

from collections import Counter
import math

from grasp_torque_opt.control.parameters.limits import MAX_GRAVITY
from grasp_torque_opt.core.exceptions import FrameNotFound, InputError
import numpy as np
import pinocchio as pin

#: A quaternion is accepted when | ||q|| - 1 | is at most this, then normalized.
QUATERNION_TOLERANCE = 1e-3
#: |joint position| above this [rad or m] is a corrupted message, not a hand.
MAX_ABS_JOINT_POSITION = 1e3
#: Names and frames in error messages are cut to this many characters.
SHOWN_NAME_LENGTH = 64


def show(name: str) -> str:
    """Quote a name in messages, cut to :data:`SHOWN_NAME_LENGTH` characters."""
    return name if len(name) <= SHOWN_NAME_LENGTH else name[:SHOWN_NAME_LENGTH] + '...'


def finite(a: np.ndarray, name: str) -> np.ndarray:
    """
    Return ``a`` as a float array.

    Raises:
        InputError: NaN or Inf in it (the field ``name``).
    """
    a = np.asarray(a, dtype=float)
    if not np.all(np.isfinite(a)):
        raise InputError(name, 'must be finite (NaN or Inf found)')
    return a


def quaternion_matrix(xyzw: np.ndarray, name: str) -> np.ndarray:
    """
    Rotation matrix of a unit quaternion (x, y, z, w).

    Raises:
        InputError: not finite, or its norm is off 1 by more than
            :data:`QUATERNION_TOLERANCE`.
    """
    q = finite(xyzw, name)
    norm = float(np.linalg.norm(q))
    if abs(norm - 1.0) > QUATERNION_TOLERANCE:
        raise InputError(name, f'is not a unit quaternion (norm {norm:.6g})')
    x, y, z, w = q / norm
    return pin.Quaternion(w, x, y, z).toRotationMatrix()


def check_joint_names(names: list[str], positions: list[float], q: np.ndarray,
                      model_joints: dict[str, int], joints: list[str]) -> tuple:
    """
    Check a joint state's names and used positions and write them into q.

    Args:
        names: the state's joint names.
        positions: their positions [rad or m].
        q: the configuration to write the model joints' positions into.
        model_joints: model joint name -> its index in q (one-dof joints).
        joints: the commanded joints, which must all be given.

    Returns:
        (names, indices of the model joints' entries, their indices in q, ``joints``):
        what lets the next state with the same names skip these checks.

    Raises:
        InputError: length mismatch, empty or duplicate name, a commanded joint
            missing, a used position not finite or beyond :data:`MAX_ABS_JOINT_POSITION`.
    """
    if len(names) != len(positions):
        raise InputError('joint_states', f'{len(names)} names but '
                         f'{len(positions)} positions')
    if len(set(names)) != len(names):
        dup = next(n for n, k in Counter(names).items() if k > 1)
        raise InputError('joint_states', f"duplicate joint name '{show(dup)}'")
    if any(not n for n in names):
        raise InputError('joint_states', 'empty joint name')
    given = set(names)
    missing = [n for n in joints if n not in given]
    if missing:
        raise InputError('joint_states', 'missing commanded joint(s) '
                         f"{', '.join(missing[:4])}")
    used, to = [], []
    for k, (name, value) in enumerate(zip(names, positions)):
        iq = model_joints.get(name)
        if iq is None:
            continue
        if not math.isfinite(value):
            raise InputError('joint_states', f"position of '{name}' is not finite")
        if abs(value) > MAX_ABS_JOINT_POSITION:
            raise InputError('joint_states', f"position of '{name}' is {value:.6g}, "
                             f'beyond +-{MAX_ABS_JOINT_POSITION:g}')
        q[iq] = value
        used.append(k)
        to.append(iq)
    return (list(names), np.array(used, dtype=np.intp), np.array(to, dtype=np.intp), joints)


def check_joint_limits(q: np.ndarray, used: np.ndarray, lower: np.ndarray,
                       upper: np.ndarray, names: dict[int, str], tolerance: float) -> None:
    """
    Refuse a used position beyond its joint's URDF limits plus ``joint_limit_tolerance``.

    Args:
        q: the configuration, shape (nq,).
        used: the indices in q the joint state gave.
        lower: the lower limits minus the tolerance, shape (nq,).
        upper: the upper limits plus the tolerance, shape (nq,).
        names: index in q -> joint name, for the message.
        tolerance: ``joint_limit_tolerance`` [rad or m].

    Raises:
        InputError: naming the joint, its position and its limits.
    """
    values = q[used]
    ok = (values >= lower[used]) & (values <= upper[used])
    if ok.all():
        return
    k = int(used[int(np.argmin(ok))])
    raise InputError('joint_states', f"position of '{names.get(k, k)}' is {q[k]:.6g}, beyond "
                     f'its URDF limits [{lower[k] + tolerance:.6g}, {upper[k] - tolerance:.6g}] '
                     f'by more than joint_limit_tolerance ({tolerance:g})')


def contact_rotations(model: pin.Model, p: int, frame: str, positions: np.ndarray,
                      quaternions: np.ndarray) -> np.ndarray:
    """
    Check contact poses (one per scenario contact) and return their rotations.

    Args:
        model: the hand's model.
        p: the scenario's number of contacts.
        frame: model frame of the poses ('' = the base frame).
        positions: contact points, shape (p, 3) [m].
        quaternions: contact frame orientations (x, y, z, w), shape (p, 4).

    Returns:
        The rotations, shape (p, 3, 3).

    Raises:
        InputError: wrong shape, unknown frame, non-finite values, a non-unit
            quaternion.
    """
    if positions.shape != (p, 3) or quaternions.shape != (p, 4):
        raise InputError('contacts', f'positions of shape {positions.shape} and '
                         f'quaternions of shape {quaternions.shape}, expected '
                         f'({p}, 3) and ({p}, 4)')
    if frame and not model.existFrame(frame):
        raise FrameNotFound('contacts.header.frame_id', show(frame),
                            {f.name for f in model.frames})
    finite(positions, 'contacts.poses.position')
    return np.array([quaternion_matrix(quaternions[i], f'contacts.poses[{i}].orientation')
                     for i in range(p)])


def checked_wrench(model: pin.Model, frame: str, force: np.ndarray, torque: np.ndarray,
                   max_force: float, max_torque: float) -> np.ndarray:
    """
    Check a load and return it as [F, M] in the axes of ``frame``.

    Raises:
        InputError: unknown frame, non-finite values, a force or moment norm above
            ``max_wrench_force`` / ``max_wrench_torque``.
    """
    if frame and not model.existFrame(frame):
        raise FrameNotFound('external_wrench.header.frame_id', show(frame),
                            {f.name for f in model.frames})
    w = np.concatenate((finite(force, 'external_wrench.wrench.force'),
                        finite(torque, 'external_wrench.wrench.torque')))
    if w.shape != (6,):
        raise InputError('external_wrench.wrench', f'{w.size} values, expected 6')
    for part, v, bound, key, unit in ((
            'force', w[:3], max_force, 'max_wrench_force', 'N'), (
            'torque', w[3:], max_torque, 'max_wrench_torque', 'N m')):
        with np.errstate(over='ignore'):  # 1e308 entries: an infinite norm
            norm = float(np.linalg.norm(v))
        if norm > bound:
            raise InputError(f'external_wrench.wrench.{part}',
                             f'norm {norm:.6g} {unit} exceeds {key} '
                             f'({bound} {unit})')
    return w


def checked_gravity(base: str, frame: str, vector: np.ndarray, rotation: np.ndarray | None,
                    unresolved: str, bounds: tuple[float, float] = (0.0, MAX_GRAVITY)
                    ) -> np.ndarray:
    """
    Check gravity and return it in base axes [m/s^2].

    Args:
        base: the hand's base frame.
        frame: the frame of the vector ('' or ``base``, or any frame with ``rotation``).
        vector: gravity in ``frame`` [m/s^2], shape (3,).
        rotation: base-from-frame rotation, shape (3, 3), or None.
        unresolved: why ``frame`` could not be looked up (for the message).
        bounds: ``gravity_norm_bounds``, [low, high] [m/s^2].

    Raises:
        InputError: another frame without ``rotation``, not finite, a norm above
            :data:`MAX_GRAVITY` or outside ``bounds``.
    """
    if frame not in ('', base) and rotation is None:
        raise InputError('gravity.header.frame_id', f"'{show(frame)}' is not the "
                         f"hand's base frame '{base}' (nor empty), and cannot be "
                         f'transformed ({unresolved})')
    g = finite(vector, 'gravity.vector')
    if g.shape != (3,):
        raise InputError('gravity.vector', f'{g.size} values, expected 3')
    if rotation is not None:
        g = finite(rotation, 'gravity.header.frame_id transform') @ g
    with np.errstate(over='ignore'):
        norm = float(np.linalg.norm(g))
    if norm > MAX_GRAVITY:
        raise InputError('gravity.vector', f'norm {norm:.6g} m/s^2 exceeds '
                         f'{MAX_GRAVITY:g} m/s^2')
    if not bounds[0] <= norm <= bounds[1]:
        raise InputError('gravity.vector', f'norm {norm:.6g} m/s^2 is outside '
                         f'gravity_norm_bounds [{bounds[0]:g}, {bounds[1]:g}]')
    return g
