# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Grasp matrix G and hand Jacobian J from the kinematics (Pinocchio).

Each contact contributes its own blocks, written in its contact frame; the
functions here only stack them.

- G (6 x 4p): maps f to the wrench on the object about the object origin c,
  base axes: G_i = [[R_i, 0], [skew(p_i - c) R_i, R_i e_z]] on [fx, fy, fz, mz].
- J (4p x m): rows of the 6 x nv Jacobian (pinocchio.LOCAL_WORLD_ALIGNED) of
  the point of the finger link that coincides with p_i, projected on x_i, y_i,
  z_i (linear part) and z_i (angular part), actuated columns only (J C, C the
  coupling's velocity map, with coupled joints: then J^T f is the actuators' u).
  With ``hand.base_link`` every point and axis is in that frame, not the model's root.
  tau = J^T f.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

from grasp_torque_opt.core.contact_frame import contact_rotations
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.hand import Hand
from grasp_torque_opt.core.scenario_fields import ContactSpec
import numpy as np
import pinocchio as pin


@dataclass(frozen=True)
class ContactFrame:
    """
    A contact frame in the base frame.

    Attributes:
        link: model frame that touches.
        frame_id: its Pinocchio frame index.
        position: contact point p_i, base frame, shape (3,) [m].
        rotation: R_i, columns x_i, y_i, z_i in base axes, shape (3, 3).
    """

    link: str
    frame_id: int
    position: np.ndarray
    rotation: np.ndarray

    @property
    def normal(self) -> np.ndarray:
        """Inward unit normal z_i, base axes."""
        return self.rotation[:, 2]

    @property
    def tangent(self) -> np.ndarray:
        """Tangent x_i, base axes."""
        return self.rotation[:, 0]


@dataclass(frozen=True)
class GraspMaps:
    """
    Kinematic maps of one grasp at one configuration.

    Attributes:
        G: grasp matrix, shape (6, 4p), about the object origin, base axes.
        J: hand Jacobian, shape (4p, m), contact frames x actuated joints.
        links: per contact, the model frame that touches.
        frame_ids: per contact, its Pinocchio frame index.
        positions: contact points p_i, base frame, shape (p, 3) [m].
        rotations: R_i, columns x_i, y_i, z_i in base axes, shape (p, 3, 3).
        object_origin: c, base frame, shape (3,) [m].
    """

    G: np.ndarray
    J: np.ndarray
    links: tuple[str, ...]
    frame_ids: tuple[int, ...]
    positions: np.ndarray
    rotations: np.ndarray
    object_origin: np.ndarray

    @property
    def p(self) -> int:
        """Return the number of contacts."""
        return len(self.links)

    @cached_property
    def contacts(self) -> list[ContactFrame]:
        """Return the contact frames, one object each (built when first asked)."""
        return [ContactFrame(link=link, frame_id=fid, position=pos, rotation=R)
                for link, fid, pos, R in zip(self.links, self.frame_ids, self.positions,
                                             self.rotations)]


#: skew(v) = [[0, -v2, v1], [v2, 0, -v0], [-v1, v0, 0]], row-major, as v[_SKEW_INDEX] * _SKEW_SIGN.
_SKEW_INDEX = np.array([0, 2, 1, 2, 0, 0, 1, 0, 0])
_SKEW_SIGN = np.array([0.0, -1.0, 1.0, 1.0, 0.0, -1.0, -1.0, 1.0, 0.0])


def _skews(v: np.ndarray) -> np.ndarray:
    """skew(v_i) for rows v_i of v, shape (n, 3, 3)."""
    return (v[:, _SKEW_INDEX] * _SKEW_SIGN).reshape(-1, 3, 3)


def compute_grasp_maps(hand: Hand, q: np.ndarray, contacts: list[ContactSpec],
                       object_origin: np.ndarray) -> GraspMaps:
    """
    Contact frames, G and J at configuration q.

    All contacts at once (batched numpy, no per-element Python loops):

    - G_i = [[R_i, 0], [skew(p_i - c) R_i, z_i]] on [fx, fy, fz, mz];
    - J_i = [R_i^T (J_v - skew(p_i - o_i) J_w); z_i^T J_w], with J_v, J_w the
      linear and angular rows of the link frame's Jacobian
      (pinocchio.LOCAL_WORLD_ALIGNED) at its origin o_i, actuated columns only.

    Args:
        hand: the hand.
        q: full configuration, shape (model.nq,).
        contacts: contacts as specified (link, point in link frame, optional
            normal and tangent in base axes).
        object_origin: c in the base frame [m].

    Raises:
        FrameNotFound: an unknown link (``grasp.contacts[i].link``).
        InputError: a normal cannot be defaulted, or a tangent is parallel.
    """
    model, data = hand.model, hand.data
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    c = np.asarray(object_origin, dtype=float)
    p = len(contacts)
    fids = tuple(hand.frame_index(spec.link, f'grasp.contacts[{i}].link')
                 for i, spec in enumerate(contacts))
    po, Rb = _points_in_base(hand, contacts, fids)
    points = po[:p]
    normals = _normals(contacts, points, c)
    R = contact_rotations(normals, [spec.tangent for spec in contacts],
                          [f'grasp.contacts[{i}]' for i in range(p)])
    # skew(v) rows for r_i = p_i - c (moments) and d_i = p_i - o_i (point velocity).
    arms = np.empty((2 * p, 3))
    np.subtract(points, c, out=arms[:p])
    np.subtract(points, po[p:], out=arms[p:])
    sk = _skews(arms)
    Rt = R.transpose(0, 2, 1)
    Gb = np.empty((6, p, 4))  # G[:, 4i + j] = Gb[:, i, j]
    Gb[:3, :, :3] = R.transpose(1, 0, 2)
    Gb[3:, :, :3] = (sk[:p] @ R).transpose(1, 0, 2)
    Gb[:3, :, 3] = 0.0
    Gb[3:, :, 3] = R[:, :, 2].T

    J6 = np.array([pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
                   for fid in fids])
    # Actuated columns: J C with coupled joints (dq = C dtheta), else a column selection.
    J6 = J6[:, :, hand.idx_v] if hand.velocity_map is None else J6 @ hand.velocity_map
    if Rb is not None:
        J6 = np.concatenate((Rb.T @ J6[:, :3], Rb.T @ J6[:, 3:]), axis=1)
    ang = J6[:, 3:]
    Jb = np.empty((p, 4, hand.m))
    # Velocity of the contact point: v_o + w x (p - o) = J_v - skew(p - o) J_w.
    Jb[:, :3] = Rt @ (J6[:, :3] - sk[p:] @ ang)
    Jb[:, 3] = (Rt[:, 2:] @ ang)[:, 0]
    return GraspMaps(G=Gb.reshape(6, 4 * p), J=Jb.reshape(4 * p, hand.m),
                     links=tuple(spec.link for spec in contacts), frame_ids=fids,
                     positions=points, rotations=R, object_origin=c)


def _points_in_base(hand: Hand, contacts: list[ContactSpec], fids: tuple[int, ...]
                    ) -> tuple[np.ndarray, np.ndarray | None]:
    """
    Return the contact points p_i, then the link origins o_i, in the base frame [m].

    Returns ``(po, Rb)``: po of shape (2p, 3); Rb the rotation of ``hand.base_link``
    in the model's world, or None without one. The frame placements must be current.
    """
    p = len(contacts)
    po = np.empty((2 * p, 3))  # contact points p_i, then link origins o_i
    for i, (spec, fid) in enumerate(zip(contacts, fids)):
        oMf = hand.data.oMf[fid]
        if spec.position is None:
            raise InputError(f'grasp.contacts[{i}].position', 'not found yet: a contact given '
                             'by its link only is found from geometry when the scenario is '
                             'bound (GraspSetup.from_scenario)')
        po[i] = oMf.act(spec.position)
        po[p + i] = oMf.translation
    Rb = None
    if hand.base_link is not None:
        # The grasp is written in hand.base_link: points, and below the Jacobians' rows, in
        # its axes (the actuated joints move only links below it: Hand.from_model).
        oMb = hand.data.oMf[hand.frame_index(hand.base_link, 'hand.base_link')]
        Rb = oMb.rotation
        po = (po - oMb.translation) @ Rb
    return po, Rb


def _normals(contacts: list[ContactSpec], points: np.ndarray,
             c: np.ndarray) -> list[np.ndarray]:
    """Return the contact normals as given, a missing one towards the object origin c."""
    normals = [spec.normal for spec in contacts]
    for i, n in enumerate(normals):
        if n is None:
            towards = c - points[i]
            if towards @ towards < 1e-18:
                raise InputError(f'grasp.contacts[{i}].normal', 'cannot default: the '
                                 'contact point coincides with grasp.object_origin')
            normals[i] = towards
    return normals
