# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Frame placements and Jacobians of many configurations at once (batch scoring's kinematics).

What :func:`grasp_torque_opt.core.grasp_maps.compute_grasp_maps` asks Pinocchio for
(``data.oMf`` and ``getFrameJacobian(..., LOCAL_WORLD_ALIGNED)`` of the contact links),
for N configurations in vectorised numpy: each joint's placement is composed for all N
at once, then each requested frame's placement and its Jacobian columns (a revolute
joint's: [a x (o_f - o_j); a], a prismatic one's: [a; 0], a and o_j the joint's world
axis and origin). Pinocchio's model supplies the tree, the joint placements and axes;
only trees of 1-DoF revolute and prismatic joints on a fixed root are taken
(:func:`supported`), and :meth:`TreeKinematics.check` holds the result to Pinocchio's
own at given configurations before it is used.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin


def _axis(model: pin.Model, data: pin.Data, j: int) -> tuple[str, np.ndarray] | None:
    """('R' or 'P', unit axis in the joint frame) of a 1-DoF joint, or None if neither."""
    joint = model.joints[j]
    if joint.nq != 1 or joint.nv != 1:
        return None
    S = np.asarray(data.joints[j].S).reshape(6)  # motion subspace [v; w] in the joint frame
    lin, ang = S[:3], S[3:]
    if np.linalg.norm(lin) < 1e-12 and abs(np.linalg.norm(ang) - 1.0) < 1e-12:
        return 'R', ang.copy()
    if np.linalg.norm(ang) < 1e-12 and abs(np.linalg.norm(lin) - 1.0) < 1e-12:
        return 'P', lin.copy()
    return None


def supported(model: pin.Model) -> str:
    """Say why :class:`TreeKinematics` cannot take this model ('' if it can)."""
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    for j in range(1, model.njoints):
        if _axis(model, data, j) is None:
            return f'joint {model.names[j]} ({model.joints[j].shortname()}) is not a ' \
                   '1-DoF revolute or prismatic joint'
    return ''


class TreeKinematics:
    """
    Placements and LOCAL_WORLD_ALIGNED Jacobians of chosen frames, for N configurations.

    Args:
        model: the hand's Pinocchio model (:func:`supported` must say '').
        module: the compiled cycle's module (its ``kinematics_batch``, the same rules in
            C++), or None for numpy.
    """

    def __init__(self, model: pin.Model, module=None) -> None:
        why = supported(model)
        if why:
            raise ValueError(why)
        self.model = model
        data = model.createData()
        pin.forwardKinematics(model, data, pin.neutral(model))
        self.nv = model.nv
        self._joints = []  # (parent, kind, axis, K, K2, R_placement, t_placement, idx_q, idx_v)
        for j in range(1, model.njoints):
            kind, a = _axis(model, data, j)
            K = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
            M = model.jointPlacements[j]
            self._joints.append((model.parents[j], kind, a, K, K @ K, M.rotation.copy(),
                                 M.translation.copy(), model.joints[j].idx_q,
                                 model.joints[j].idx_v))
        self.module = module
        nj = model.njoints
        self._tables = (
            np.array(model.parents, dtype=np.int64),
            np.array([0] + [0 if j[1] == 'R' else 1 for j in self._joints], dtype=np.int64),
            np.array([np.zeros(3)] + [j[2] for j in self._joints]),
            np.array([np.eye(3)] + [j[5] for j in self._joints]),
            np.array([np.zeros(3)] + [j[6] for j in self._joints]),
            np.array([0] + [j[7] for j in self._joints], dtype=np.int64),
            np.array([0] + [j[8] for j in self._joints], dtype=np.int64))
        assert self._tables[0].shape == (nj,)
        # Each joint's supporting joints (itself and its ancestors, not the universe).
        self._support = {j: [s for s in model.supports[j] if s > 0]
                         for j in range(model.njoints)}

    @property
    def tables(self) -> tuple[np.ndarray, ...]:
        """
        Return the joint tables as the compiled module takes them (src/tree_kinematics.hpp).

        (parents, kinds: 0 revolute, 1 prismatic; axes, shape (njoints, 3); the
        placements in the parent, Rp (njoints, 3, 3) and tp (njoints, 3); idx_q, idx_v),
        joint 0 the root.
        """
        return self._tables

    def frame_tables(self, frame_ids: tuple[int, ...]
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return (parent joints, placement rotations (p, 3, 3), translations (p, 3)) of frames."""
        frames = [self.model.frames[f] for f in frame_ids]
        return (np.array([f.parentJoint for f in frames], dtype=np.int64),
                np.array([f.placement.rotation for f in frames]).reshape(-1, 3, 3),
                np.array([f.placement.translation for f in frames]).reshape(-1, 3))

    def joints(self, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """
        World placements of every joint frame at configurations Q, shape (N, nq).

        Returns:
            (R, shape (njoints, N, 3, 3); t, shape (njoints, N, 3)); joint 0 is the root.
        """
        N = Q.shape[0]
        nj = self.model.njoints
        R = np.empty((nj, N, 3, 3))
        t = np.empty((nj, N, 3))
        R[0] = np.eye(3)
        t[0] = 0.0
        for j, (parent, kind, a, K, K2, Rp, tp, iq, _) in enumerate(self._joints, 1):
            q = Q[:, iq]
            Rpar = R[parent]
            base = Rpar @ Rp  # (N, 3, 3)
            origin = t[parent] + Rpar @ tp
            if kind == 'R':
                s, c1 = np.sin(q)[:, None, None], (1.0 - np.cos(q))[:, None, None]
                R[j] = base + base @ (s * K + c1 * K2)
                t[j] = origin
            else:
                R[j] = base
                t[j] = origin + q[:, None] * (base @ a)
        return R, t

    def frames(self, Q: np.ndarray, frame_ids: tuple[int, ...]
               ) -> tuple[np.ndarray, np.ndarray]:
        """
        Placements and Jacobians of frames at configurations Q, shape (N, nq).

        Returns:
            (oMf, shape (N, p, 4, 4); J6, shape (N, p, 6, nv), LOCAL_WORLD_ALIGNED at
            each frame's origin), as ``compiled.CompiledCycle.kinematics`` for each row.
        """
        Q = np.asarray(Q, dtype=float)
        if self.module is not None:
            return self.module.kinematics_batch(Q, *self._tables,
                                                *self.frame_tables(frame_ids), self.nv)
        N, p = Q.shape[0], len(frame_ids)
        R, t = self.joints(Q)
        oMf = np.zeros((N, p, 4, 4))
        oMf[:, :, 3, 3] = 1.0
        J6 = np.zeros((N, p, 6, self.nv))
        for i, fid in enumerate(frame_ids):
            frame = self.model.frames[fid]
            j = frame.parentJoint
            M = frame.placement
            Rf = R[j] @ M.rotation
            of = t[j] + R[j] @ M.translation
            oMf[:, i, :3, :3] = Rf
            oMf[:, i, :3, 3] = of
            for s in self._support[j]:
                _, kind, a, _, _, _, _, _, iv = self._joints[s - 1]
                axis = R[s] @ a  # (N, 3), world axes
                if kind == 'R':
                    J6[:, i, :3, iv] = np.cross(axis, of - t[s])
                    J6[:, i, 3:, iv] = axis
                else:
                    J6[:, i, :3, iv] = axis
        return oMf, J6

    def check(self, Q: np.ndarray, frame_ids: tuple[int, ...], tol: float = 1e-9) -> float:
        """
        Return the largest difference from Pinocchio's placements and Jacobians at Q.

        Raises:
            ValueError: it exceeds ``tol``.
        """
        oMf, J6 = self.frames(Q, frame_ids)
        data = self.model.createData()
        worst = 0.0
        for n, q in enumerate(np.asarray(Q, dtype=float)):
            pin.computeJointJacobians(self.model, data, q)
            pin.updateFramePlacements(self.model, data)
            for i, fid in enumerate(frame_ids):
                ref_J = pin.getFrameJacobian(self.model, data, fid, pin.LOCAL_WORLD_ALIGNED)
                worst = max(worst, float(np.abs(data.oMf[fid].homogeneous - oMf[n, i]).max()),
                            float(np.abs(ref_J - J6[n, i]).max()))
        if not worst <= tol:
            raise ValueError(f'kinematics differ from Pinocchio by {worst:.3g}')
        return worst
