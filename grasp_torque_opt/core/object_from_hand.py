# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The object's state from the hand: where the fingertips say it is, and how it moves.

Under the grasp constraint the contact points move with the object (they stick; a tip
may roll): G^T xdot = J qdot, G^T's rows for contact i being [I, -[p_i - c]x] (the
point's velocity from the object's twist [v, w] at its origin c, base axes) and J the
point's translational Jacobian. :meth:`ObjectFromHand.estimate` solves it in least
squares over the contacts:

- the displacement, finite, from a reference (the grasp's start: a joint configuration
  q0 and the object's pose there): the rigid motion that best carries the contact
  points at q0 to the same material points at q (Kabsch's solution, :func:`kabsch`: the
  rotation of ``scipy.spatial.transform.Rotation.align_vectors``, without its 60 us of
  array dispatch on every joint state; for small motions it is the least squares
  solution of G^T dx = J dq); the object's pose is that motion applied to the reference
  pose;
- the twist, from joint velocities: ``numpy.linalg.lstsq`` of G^T [v, w] = J qdot;
- the residuals: how far each contact point is from the rigid motion [m] (a slip, a
  finger off the object, or a lie of the joint states), and the worst of them.

With fewer than three contacts the rotation is not observed: the displacement is the
contact points' mean translation, the rotation none. ROS-free.

The node's object loop asks for an estimate on every joint state, where the numpy
above costs about 80 us (the SVD of a 3 x 3 matrix alone 13 us of numpy's dispatch).
Given the compiled module (``grasp_torque_opt.native.loader.fast_cycle``, handed down:
core imports nothing above it) and a hand that is a tree of 1-DoF joints, the points
and the fit are computed there (``TreePoints`` in src/tree_kinematics.hpp, the same
rules in Eigen), held to Pinocchio's points at the reference before use; the numpy path
stays the reference the tests hold it to.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from grasp_torque_opt.core.hand import Hand
from grasp_torque_opt.core.scenario_fields import ContactSpec
from grasp_torque_opt.core.tree_kinematics import TreeKinematics
import numpy as np
import pinocchio as pin

#: The compiled points may differ from Pinocchio's by this much at the reference [m]
#: (rounding: they agree to about 1e-16).
POINTS_TOLERANCE = 1e-12


@dataclass(frozen=True)
class ObjectEstimate:
    """
    The object's state the fingertips give.

    Attributes:
        pose: the object's frame in the base frame.
        translation: its origin's displacement from the reference, base axes [m], (3,).
        rotation: its rotation from the reference, a rotation vector in base axes [rad], (3,).
        twist: [v, w] of the object at its origin, base axes [m/s, rad/s], shape (6,),
            or None (no joint velocities given).
        residual: the largest distance of a contact point from the rigid motion [m].
        residuals: each contact point's distance from the rigid motion [m], shape (p,).
    """

    pose: pin.SE3
    translation: np.ndarray
    rotation: np.ndarray
    twist: np.ndarray | None
    residual: float
    residuals: np.ndarray = field(default_factory=lambda: np.zeros(0))


def kabsch(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """
    Return the rotation R that minimises sum ||a_i - R b_i||^2 (Kabsch's solution).

    ``a`` and ``b``, shape (n, 3), centred. The SVD of B = a^T b, its last singular
    direction turned where det(U V^T) < 0 (a reflection is never returned), as
    ``scipy.spatial.transform.Rotation.align_vectors(a, b)`` computes it unweighted.
    """
    u, _, vh = np.linalg.svd(a.T @ b)
    r = u @ vh
    det = (r[0, 0] * (r[1, 1] * r[2, 2] - r[1, 2] * r[2, 1])
           - r[0, 1] * (r[1, 0] * r[2, 2] - r[1, 2] * r[2, 0])
           + r[0, 2] * (r[1, 0] * r[2, 1] - r[1, 1] * r[2, 0]))
    if det < 0.0:
        u[:, 2] = -u[:, 2]
        r = u @ vh
    return r


class ObjectFromHand:
    """
    The object's pose and twist from the fingertips' kinematics, from a reference.

    Args:
        hand: the hand (its model; its base link, whose frame the poses are in).
        contacts: the contacts (each a material point of its link: ``position`` in the
            link's frame).
        q0: the reference configuration, shape (model.nq,) (coupled joints completed).
        pose0: the object's frame in the base frame at ``q0``.
        module: the compiled module whose ``TreePoints`` computes the points and the
            fit where it takes the hand (:attr:`compiled` says whether it does), or
            None: numpy's and Pinocchio's.

    Keeps its own Pinocchio data: not shared across threads.
    """

    def __init__(self, hand: Hand, contacts: list[ContactSpec], q0: np.ndarray,
                 pose0: pin.SE3, module=None) -> None:
        self.hand = hand
        model = hand.model
        self._data = model.createData()
        self._frames = [model.getFrameId(c.link) for c in contacts]
        self._local = np.array([np.asarray(c.position, dtype=float)
                                for c in contacts]).reshape(-1, 3)
        self._base = None if hand.base_link is None else model.getFrameId(hand.base_link)
        #: The compiled points and fit (None: numpy's and Pinocchio's).
        self.compiled = None if module is None else self._compiled(module, q0)
        self.reset(q0, pose0)

    def _compiled(self, module, q0: np.ndarray):
        """Return the module's points of this hand's contacts, if it takes them (else None)."""
        model = self.hand.model
        if not self._frames:
            return None
        try:
            tree = TreeKinematics(model)
        except ValueError:  # not a tree of 1-DoF joints (its own check: supported)
            return None
        base = (-1, np.eye(3), np.zeros(3)) if self._base is None else \
            (b[0] for b in tree.frame_tables((self._base,)))
        points = module.TreePoints(*tree.tables, model.nq, model.nv,
                                   *tree.frame_tables(tuple(self._frames)), self._local, *base)
        q0 = np.asarray(q0, dtype=float)
        if not np.abs(points.points(q0) - self.points(q0)).max() <= POINTS_TOLERANCE:
            return None  # never expected for a tree the module takes: numpy's then
        return points

    def reset(self, q0: np.ndarray, pose0: pin.SE3) -> None:
        """Take a new reference: the object at ``pose0`` when the hand is at ``q0``."""
        self.q0 = np.array(q0, dtype=float)
        self.pose0 = pose0.copy()
        self.points0 = self.points(self.q0)

    def points(self, q: np.ndarray) -> np.ndarray:
        """Return the contact points at ``q``, base frame, shape (p, 3) [m]."""
        model, data = self.hand.model, self._data
        pin.framesForwardKinematics(model, data, q)
        return self._placed(data)

    def _placed(self, data: pin.Data) -> np.ndarray:
        world = np.array([data.oMf[f].act(p) for f, p in zip(self._frames, self._local)])
        if self._base is None:
            return world
        oMb = data.oMf[self._base]
        return (world - oMb.translation) @ oMb.rotation

    def estimate(self, q: np.ndarray, v: np.ndarray | None = None) -> ObjectEstimate:
        """
        Return the object's state at ``q`` (and joint velocities ``v``, shape (model.nv,)).

        Args:
            q: the configuration, shape (model.nq,) (coupled joints completed).
            v: the joint velocities (coupled joints completed), or None: no twist.
        """
        p0 = self.points0
        if self.compiled is not None:
            R, t, p, residuals = self.compiled.estimate(q, p0)
        else:
            p = self.points(q)
            m0, m = p0.mean(axis=0), p.mean(axis=0)
            R = kabsch(p - m, p0 - m0) if len(p) >= 3 else np.eye(3)
            t = m - R @ m0
            d = p - (p0 @ R.T + t)
            residuals = np.sqrt((d * d).sum(axis=1))
        pose = pin.SE3(R, t) * self.pose0
        twist = None if v is None else self._twist(q, v, p, pose.translation)
        return ObjectEstimate(pose, pose.translation - self.pose0.translation, pin.log3(R),
                              twist, float(residuals.max()), residuals)

    def _twist(self, q: np.ndarray, v: np.ndarray, points: np.ndarray, c: np.ndarray
               ) -> np.ndarray:
        """Solve G^T [v, w] = J qdot in least squares (base axes, about ``c``)."""
        model, data = self.hand.model, self._data
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        rows, rhs = [], []
        for f, local, point in zip(self._frames, self._local, points):
            rhs.append(self._point_velocity(f, local, v))
            r = point - c
            rows.append(np.hstack((np.eye(3), -pin.skew(r))))
        x, *_ = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)
        return x

    def _point_velocity(self, frame: int, local: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Return a material point's velocity relative to the base, base axes [m/s]."""
        model, data = self.hand.model, self._data
        world = data.oMf[frame].act(local)

        def velocity(f: int) -> np.ndarray:
            J = pin.getFrameJacobian(model, data, f, pin.LOCAL_WORLD_ALIGNED) @ v
            return J[:3] + np.cross(J[3:], world - data.oMf[f].translation)
        if self._base is None:
            return velocity(frame)
        return data.oMf[self._base].rotation.T @ (velocity(frame) - velocity(self._base))
