"""Grasp matrix G and hand Jacobian J from the kinematics (Pinocchio).

Each contact contributes its own blocks, written in its contact frame; the
functions here only stack them.

- G (6 x 4p): maps f to the wrench on the object about the object origin c,
  base axes: G_i = [[R_i, 0], [skew(p_i - c) R_i, R_i e_z]] on [fx, fy, fz, mz].
- J (4p x m): rows of the 6 x nv Jacobian (pinocchio.LOCAL_WORLD_ALIGNED) of
  the point of the finger link that coincides with p_i, projected on x_i, y_i,
  z_i (linear part) and z_i (angular part), actuated columns only.
  tau = J^T f.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from grasp_torque_opt.contact_frame import contact_rotations
from grasp_torque_opt.exceptions import InputError
from grasp_torque_opt.hand import Hand
from grasp_torque_opt.scenario import ContactSpec


@dataclass(frozen=True)
class ContactFrame:
    """A contact frame in the base frame.

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
    """Kinematic maps of one grasp at one configuration.

    Attributes:
        G: grasp matrix, shape (6, 4p), about the object origin, base axes.
        J: hand Jacobian, shape (4p, m), contact frames x actuated joints.
        contacts: the contact frames.
        object_origin: c, base frame, shape (3,) [m].
    """

    G: np.ndarray
    J: np.ndarray
    contacts: list[ContactFrame]
    object_origin: np.ndarray

    @property
    def p(self) -> int:
        """Number of contacts."""
        return len(self.contacts)


def _skews(v: np.ndarray) -> np.ndarray:
    """skew(v_i) for rows v_i of v, shape (n, 3, 3)."""
    out = np.zeros((len(v), 3, 3))
    out[:, 0, 1], out[:, 0, 2], out[:, 1, 2] = -v[:, 2], v[:, 1], -v[:, 0]
    out[:, 1, 0], out[:, 2, 0], out[:, 2, 1] = v[:, 2], -v[:, 1], v[:, 0]
    return out


def compute_grasp_maps(hand: Hand, q: np.ndarray, contacts: list[ContactSpec],
                       object_origin: np.ndarray) -> GraspMaps:
    """Contact frames, G and J at configuration q.

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
    fields = [f"grasp.contacts[{i}]" for i in range(p)]
    fids = [hand.frame_index(spec.link, f"{field}.link")
            for spec, field in zip(contacts, fields)]
    origins, points, normals = [], [], []
    for spec, fid, field in zip(contacts, fids, fields):
        oMf = data.oMf[fid]
        o = oMf.translation
        pt = oMf.act(np.asarray(spec.position, dtype=float))
        normal = spec.normal
        if normal is None:
            normal = c - pt
            if normal @ normal < 1e-18:
                raise InputError(f"{field}.normal", "cannot default: the contact point "
                                 "coincides with grasp.object_origin")
        origins.append(o)
        points.append(pt)
        normals.append(normal)
    points = np.array(points)
    R = contact_rotations(np.array(normals), [spec.tangent for spec in contacts], fields)
    # skew(v) rows for r_i = p_i - c (moments) and d_i = p_i - o_i (point velocity).
    sk = _skews(np.concatenate((points - c, points - np.array(origins))))
    Gb = np.zeros((p, 6, 4))
    Gb[:, :3, :3] = R
    Gb[:, 3:, :3] = sk[:p] @ R
    Gb[:, 3:, 3] = R[:, :, 2]

    J6 = np.array([pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
                   for fid in fids])[:, :, hand.idx_v]
    ang = J6[:, 3:]
    Jb = np.empty((p, 4, hand.m))
    # Velocity of the contact point: v_o + w x (p - o) = J_v - skew(p - o) J_w.
    Jb[:, :3] = R.transpose(0, 2, 1) @ (J6[:, :3] - sk[p:] @ ang)
    Jb[:, 3] = (R[:, :, 2:].transpose(0, 2, 1) @ ang)[:, 0]

    frames = [ContactFrame(link=spec.link, frame_id=fid, position=points[i], rotation=R[i])
              for i, (spec, fid) in enumerate(zip(contacts, fids))]
    return GraspMaps(G=Gb.transpose(1, 0, 2).reshape(6, 4 * p), J=Jb.reshape(4 * p, hand.m),
                     contacts=frames, object_origin=c)
