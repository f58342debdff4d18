# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The planner's IK: contact links onto the object's surface, every other shape clear of it.

One problem per candidate, over the actuated joint positions theta and the object's
position p (its orientation fixed), solved by SciPy's ``least_squares`` (trust region
reflective, with bounds) with an analytic Jacobian:

    residuals  d_c(theta, p)                        each contact link's signed distance
               max(0, clearance' - d_k(theta, p))   every other collision shape (palm too)
               w_q (theta - theta_seed), w_p (p - p_seed)   a weak pull to the sample
    bounds     joint limits (minus a margin), p in the reach region

The distances are coal's (signed: GJK, EPA when they overlap) between each of the
URDF's collision shapes and the object. The derivative of a distance d between a
link's point p1 and the object's p2 along the unit normal n (link to object) is
-n . v(p1) for the link's motion and +n . v_object for the object's.
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
from grasp_torque_opt.core.geometry_contacts import collision_model
from grasp_torque_opt.core.hand import Hand
from grasp_torque_opt.core.object_geometry import coal_shape, ObjectShape
import numpy as np
import pinocchio as pin
from scipy.optimize import least_squares

#: Weight of the pull towards the sampled joint positions [m/rad].
PULL_JOINTS = 2e-3
#: Weight of the pull towards the sampled object position [-].
PULL_OBJECT = 2e-2
#: Weight of a contact's distance past the keep-off band of an edge [-].
EDGE_WEIGHT = 1.0


@dataclass(frozen=True)
class IKResult:
    """One IK's answer: the actuated joint positions, the object's position, its cost."""

    theta: np.ndarray
    position: np.ndarray
    cost: float
    success: bool


class SurfaceIK:
    """Every collision shape of one hand against one object: distances, Jacobians, the IK."""

    def __init__(self, hand: Hand, urdf, shape: ObjectShape, contact_links: list[str],
                 edge: float = 0.0) -> None:
        """Bind the hand's collision shapes and the object once (``edge``: keep off edges)."""
        self.hand = hand
        self.shape = shape
        self.edge = edge
        self.model = hand.model
        self.data = hand.model.createData()
        self.geom = collision_model(hand, urdf)
        self.gdata = pin.GeometryData(self.geom)
        self._owner = coal_shape(shape)  # ComputeDistance keeps a pointer: keep it alive
        self.request = coal.DistanceRequest()
        self.result = coal.DistanceResult()
        self.computes = [coal.ComputeDistance(g.geometry, self._owner)
                         for g in self.geom.geometryObjects]
        frames = [self.model.frames[g.parentFrame].name for g in self.geom.geometryObjects]
        self.shape_link = frames
        self.contact_links = list(contact_links)
        self.contact_shapes = [[i for i, f in enumerate(frames) if f == link]
                               for link in self.contact_links]
        taken = {i for shapes in self.contact_shapes for i in shapes}
        self.other_shapes = [i for i in range(len(frames)) if i not in taken]
        base = hand.base_link
        self.base = None if base is None else self.model.getFrameId(base)
        self.C = hand.velocity_map

    def full_q(self, theta: np.ndarray, q_base: np.ndarray) -> np.ndarray:
        """Return the full configuration: ``q_base`` with the actuated joints at theta."""
        q = q_base.copy()
        q[self.hand.idx_q] = theta
        return self.hand.complete(q)

    def _base(self) -> pin.SE3:
        if self.base is None:
            return pin.SE3.Identity()
        pin.updateFramePlacement(self.model, self.data, self.base)
        return self.data.oMf[self.base]

    def evaluate(self, q: np.ndarray, pose: pin.SE3, jacobians: bool = False) -> list[tuple]:
        """
        Return per collision shape its distance, derivatives and nearest point.

        Each row: (signed distance [m], d(distance)/d(theta), d/d(p), the object's
        nearest point in its frame, that point's velocity columns there).

        All but the distance are None unless ``jacobians``; p is the object's position
        in the base frame; the point is taken as moving with the link.
        """
        model, data = self.model, self.data
        pin.forwardKinematics(model, data, q)
        pin.updateGeometryPlacements(model, data, self.geom, self.gdata)
        oMb = self._base()
        oMo = oMb * pose
        tf = coal.Transform3s(oMo.rotation, oMo.translation)
        Jb = None
        if jacobians:
            pin.computeJointJacobians(model, data, q)
            if self.base is not None:  # the base moves with q too (a hand in a robot)
                Jb = pin.getFrameJacobian(model, data, self.base, pin.LOCAL_WORLD_ALIGNED)
        out = []
        for i, g in enumerate(self.geom.geometryObjects):
            oMg = self.gdata.oMg[i]
            res = self.result
            res.clear()
            d = self.computes[i](coal.Transform3s(oMg.rotation, oMg.translation), tf,
                                 self.request, res)
            if not jacobians:
                out.append((float(d), None, None, None, None))
                continue
            n = np.asarray(res.normal, dtype=float)
            n = n / max(np.linalg.norm(n), 1e-12)
            p1 = np.asarray(res.getNearestPoint1(), dtype=float)
            J = pin.getJointJacobian(model, data, g.parentJoint, pin.LOCAL_WORLD_ALIGNED)
            r = p1 - data.oMi[g.parentJoint].translation
            v = J[:3] - np.cross(r, J[3:].T).T  # the point's velocity columns
            dq = -n @ v
            if Jb is not None:  # the object's point moves with the base
                rb = np.asarray(res.getNearestPoint2(), dtype=float) - oMb.translation
                dq = dq + n @ (Jb[:3] - np.cross(rb, Jb[3:].T).T)
            dtheta = dq[self.hand.idx_v] if self.C is None else dq @ self.C
            vtheta = v[:, self.hand.idx_v] if self.C is None else v @ self.C
            local = oMo.actInv(np.asarray(res.getNearestPoint2(), dtype=float))
            out.append((float(d), dtheta, oMb.rotation.T @ n, local,
                        oMo.rotation.T @ vtheta))
        return out

    def distances(self, q: np.ndarray, pose: pin.SE3) -> dict[str, float]:
        """Return every link's least signed distance to the object [m] (palm included)."""
        out: dict[str, float] = {}
        for link, (d, *_) in zip(self.shape_link, self.evaluate(q, pose)):
            out[link] = min(d, out.get(link, np.inf))
        return out

    def _edge_rows(self, x, vx, rotation, f, J, row) -> None:
        """
        Two rows that keep a contact's object point ``x`` off the edges (box, cylinder).

        For each direction along the contact's face: how far the point is past
        ``2 edge`` from the face's border (0 inside), with its derivative (the point
        moving with the link, ``vx`` its velocity columns in the object's axes, and
        against the object's translation).
        """
        size, keep = self.shape.size, 2.0 * self.edge
        if self.shape.kind == 'box':
            half = 0.5 * size
            face = int(np.argmax(np.abs(x) - half))
            axes = [a for a in range(3) if a != face]
            grads = []
            for a in axes:
                unit = np.zeros(3)
                unit[a] = np.sign(x[a])
                grads.append((abs(x[a]) - (half[a] - keep), unit))
        else:
            r, h = size[0], 0.5 * size[1]
            rho = float(np.hypot(x[0], x[1]))
            if r - rho < h - abs(x[2]):  # on the side: keep off the rims
                grads = [(abs(x[2]) - (h - keep), np.array([0.0, 0.0, np.sign(x[2])]))]
            else:  # on a cap: keep inside its rim
                radial = np.array([x[0], x[1], 0.0]) / max(rho, 1e-12)
                grads = [(rho - (r - keep), radial)]
        for j, (gap, unit) in enumerate(grads):
            if gap > 0.0:
                f[row + j] = EDGE_WEIGHT * gap
                J[row + j, :vx.shape[1]] = EDGE_WEIGHT * (unit @ vx)
                J[row + j, -3:] = -EDGE_WEIGHT * (rotation @ unit)

    def solve(self, theta0: np.ndarray, p0: np.ndarray, rotation: np.ndarray,
              q_base: np.ndarray, bounds: tuple[np.ndarray, np.ndarray],
              region: tuple[np.ndarray, np.ndarray], clearance: float,
              max_evaluations: int = 60) -> IKResult:
        """
        Solve one IK from a sampled start (theta0, p0), the object's rotation fixed.

        Args:
            theta0: start (and pull target) of the actuated joints [rad].
            p0: start (and pull target) of the object's position [m], base frame.
            rotation: the object's orientation in the base frame, (3, 3).
            q_base: the full configuration the other joints are taken from.
            bounds: lower and upper bounds of theta.
            region: lower and upper corners of the object's position.
            clearance: the distance every other shape keeps from the object [m].
            max_evaluations: residual evaluations at most.
        """
        m = self.hand.m
        c = len(self.contact_links)
        target = 1.25 * clearance  # a little more than asked: the check is strict

        def split(x):
            return x[:m], x[m:]

        edges = self.edge > 0.0 and self.shape.kind in ('box', 'cylinder')

        def residuals(x, want_jac=False):
            want_jac = want_jac or edges  # the edge rows need the object point
            theta, p = split(x)
            rows = self.evaluate(self.full_q(theta, q_base), pin.SE3(rotation, p), want_jac)
            f = np.zeros(c + len(self.other_shapes) + m + 3 + 2 * c)
            J = np.zeros((f.size, m + 3)) if want_jac else None
            e = f.size - 2 * c
            for k, shapes in enumerate(self.contact_shapes):
                i = min(shapes, key=lambda s: rows[s][0])
                f[k] = rows[i][0]
                if want_jac:
                    J[k, :m], J[k, m:] = rows[i][1], rows[i][2]
                if edges:
                    self._edge_rows(rows[i][3], rows[i][4], rotation, f, J, e + 2 * k)
            for k, i in enumerate(self.other_shapes, c):
                gap = target - rows[i][0]
                f[k] = max(gap, 0.0)
                if want_jac and gap > 0.0:
                    J[k, :m], J[k, m:] = -rows[i][1], -rows[i][2]
            k = c + len(self.other_shapes)
            f[k:k + m] = PULL_JOINTS * (theta - theta0)
            f[k + m:k + m + 3] = PULL_OBJECT * (p - p0)
            if want_jac:
                J[k:k + m, :m] = PULL_JOINTS * np.eye(m)
                J[k + m:k + m + 3, m:] = PULL_OBJECT * np.eye(3)
            return f, J

        lower = np.concatenate([bounds[0], region[0]])
        upper = np.concatenate([bounds[1], region[1]])
        x0 = np.clip(np.concatenate([theta0, p0]), lower, upper)
        sol = least_squares(lambda x: residuals(x)[0], x0, jac=lambda x: residuals(x, True)[1],
                            bounds=(lower, upper), method='trf', max_nfev=max_evaluations,
                            xtol=1e-10, ftol=1e-10, gtol=1e-10)
        theta, p = split(sol.x)
        return IKResult(theta=theta, position=p, cost=float(sol.cost), success=sol.status > 0)
