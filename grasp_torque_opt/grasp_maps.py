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

from grasp_torque_opt.contact_frame import contact_rotation
from grasp_torque_opt.exceptions import FrameNotFound, InputError
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


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def frame_id(model: pin.Model, name: str, field: str) -> int:
    """Index of a model frame by name.

    Raises:
        FrameNotFound: naming ``field``.
    """
    if not model.existFrame(name):
        raise FrameNotFound(field, name, {f.name for f in model.frames})
    return model.getFrameId(name)


def grasp_block(frame: ContactFrame, object_origin: np.ndarray) -> np.ndarray:
    """G_i, shape (6, 4): wrench on the object about c of f_i = [fx, fy, fz, mz]."""
    R = frame.rotation
    G_i = np.zeros((6, 4))
    G_i[:3, :3] = R
    G_i[3:, :3] = _skew(frame.position - object_origin) @ R
    G_i[3:, 3] = R[:, 2]
    return G_i


def jacobian_block(frame: ContactFrame, J6: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """J_i, shape (4, nv): contact-frame rows of the contact point's Jacobian.

    Args:
        frame: the contact frame.
        J6: 6 x nv Jacobian of the link frame, pinocchio.LOCAL_WORLD_ALIGNED
            (linear velocity of the frame origin, angular velocity; base axes).
        origin: the link frame origin, base frame [m].
    """
    lin = J6[:3] - _skew(frame.position - origin) @ J6[3:]
    R = frame.rotation
    return np.vstack((R.T @ lin, R[:, 2] @ J6[3:]))


def compute_grasp_maps(hand: Hand, q: np.ndarray, contacts: list[ContactSpec],
                       object_origin: np.ndarray) -> GraspMaps:
    """Contact frames, G and J at configuration q.

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
    model = hand.model
    data = hand.data
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    c = np.asarray(object_origin, dtype=float)
    frames, G_blocks, J_blocks = [], [], []
    for i, spec in enumerate(contacts):
        field = f"grasp.contacts[{i}]"
        fid = frame_id(model, spec.link, f"{field}.link")
        oMf = data.oMf[fid]
        p = oMf.act(np.asarray(spec.position, dtype=float))
        normal = spec.normal
        if normal is None:
            d = c - p
            if np.linalg.norm(d) < 1e-9:
                raise InputError(f"{field}.normal", "cannot default: the contact point "
                                 "coincides with grasp.object_origin")
            normal = d
        frame = ContactFrame(link=spec.link, frame_id=fid, position=p,
                             rotation=contact_rotation(normal, spec.tangent, field))
        J6 = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        frames.append(frame)
        G_blocks.append(grasp_block(frame, c))
        J_blocks.append(jacobian_block(frame, J6, oMf.translation)[:, hand.idx_v])
    return GraspMaps(G=np.hstack(G_blocks), J=np.vstack(J_blocks), contacts=frames,
                     object_origin=c)
