# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Contact normals must point into the object: a normal pointing out of it is a pull.

The friction cone only lets a contact push along its normal z_i, so a normal pointing
away from the object turns every "push" into a pull on the object: the QP is then
certified (it is consistent with itself) with torques of the opposite sign, and the
object falls. Two checks, on the contact points and normals in the base frame
(docs/design.md section 4.1):

- towards ``grasp.object_origin``: z_i . (c - p_i) must not be negative;
- where the scenario gives the object's shape, against its surface: z_i . n_in(p_i)
  must not be negative, with n_in the inward normal of the shape's nearest face
  (sphere: towards its centre; box: the face whose half-extent the point is closest
  to crossing; cylinder: the side or the nearer cap, the same way).
"""

from __future__ import annotations

from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.scenario import ObjectSpec
import numpy as np
import pinocchio as pin


def surface_inward_normal(obj: ObjectSpec, point: np.ndarray) -> np.ndarray | None:
    """
    Return the inward unit normal of the object's nearest face at ``point``, base axes.

    Args:
        obj: the object (shape, size [m], position [m] and rpy [rad] in the base frame).
        point: a point in the base frame [m], shape (3,).

    Returns:
        The unit normal, shape (3,), or None at the shape's centre (no nearest face).
    """
    R = pin.rpy.rpyToMatrix(*obj.rpy)
    local = R.T @ (np.asarray(point, dtype=float) - obj.position)
    if obj.shape == 'sphere':
        out = local
    elif obj.shape == 'box':
        ratios = np.abs(local) / (0.5 * obj.size)
        k = int(np.argmax(ratios))
        out = np.zeros(3)
        out[k] = np.sign(local[k])
    else:  # cylinder, axis z: [radius, length]
        radial = float(np.hypot(local[0], local[1]))
        if radial / obj.size[0] >= abs(local[2]) / (0.5 * obj.size[1]):
            out = np.array([local[0], local[1], 0.0])
        else:
            out = np.array([0.0, 0.0, np.sign(local[2])])
    norm = float(np.linalg.norm(out))
    if norm < 1e-12:
        return None
    return -(R @ out) / norm


def check_inward_normals(positions: np.ndarray, normals: np.ndarray, links: tuple[str, ...],
                         origin: np.ndarray, obj: ObjectSpec | None = None) -> None:
    """
    Refuse a contact whose normal points out of the object.

    Args:
        positions: contact points p_i, base frame, shape (p, 3) [m].
        normals: unit normals z_i, base axes, shape (p, 3).
        links: the contacts' links, for messages.
        origin: the object origin c, base frame, shape (3,) [m].
        obj: the object, if the scenario gives it.

    Raises:
        InputError: ``grasp.contacts[i].normal``, naming the contact and the direction
            it should point to.
    """
    c = np.asarray(origin, dtype=float)
    for i, (p, n) in enumerate(zip(positions, normals)):
        field = f'grasp.contacts[{i}].normal'
        towards = c - p
        dist = float(np.linalg.norm(towards))
        if dist > 1e-12 and float(n @ towards) < 0.0:
            raise InputError(field, f"the normal of the contact on '{links[i]}' points away "
                             f'from grasp.object_origin (component {n @ towards / dist:.3g} '
                             'along the way to it): a normal must point into the object '
                             '(the contact pushes along it), else the torques pull')
        if obj is None:
            continue
        inward = surface_inward_normal(obj, p)
        if inward is not None and float(n @ inward) < 0.0:
            raise InputError(field, f"the normal of the contact on '{links[i]}' points out "
                             f"of the object's {obj.shape} surface (component "
                             f'{n @ inward:.3g} along its inward normal '
                             f'{np.round(inward, 3).tolist()}): a normal must point into '
                             'the object (the contact pushes along it), else the torques pull')
