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
position p (its orientation fixed), solved by a bounded Levenberg-Marquardt
(:func:`levenberg_marquardt`) with an analytic Jacobian:

    residuals  d_c(theta, p)                        each contact link's signed distance
               max(0, clearance' - d_k(theta, p))   every other collision shape (palm too)
               w_q (theta - theta_seed), w_p (p - p_seed)   a weak pull to the sample
    bounds     joint limits (minus a margin), p in the reach region

The distances are coal's (signed: GJK, EPA when they overlap) between each of the
URDF's collision shapes and the object. The derivative of a distance d between a
link's point p1 and the object's p2 along the unit normal n (link to object) is
-n . v(p1) for the link's motion and +n . v_object for the object's.

Cost (issue 36): a shape of another link whose lower bound (the bounding spheres' gap,
then for a mesh coal's distance from its convex hull, which the mesh lies in) is
already past the clearance band is not measured: its row is 0 either way, so the
residuals are those of every distance measured. With meshes on the contact links, the
IK runs first on every mesh's convex hull, then, from where that met the stop test, on
the meshes themselves. One evaluation gives the residuals and their Jacobian (the rows
that are not 0 only). The IK stops at the first point that meets the check's
tolerances with a margin (:meth:`SurfaceIK.solve`'s ``tolerance``) rather than run to
the solver's own: the independent check of :mod:`.plan` judges it either way.

Why a solver of its own (issue 36): SciPy's ``least_squares`` (trust region
reflective) spent as long in its own Python per IK as the residuals did (an SVD and a
trust-region subproblem per step, about 3 ms of an Allegro IK's 6), and importing
``scipy.optimize`` took 0.3 s of the planner's start-up. These problems are small (the
Allegro: 19 unknowns, about 40 rows) and end at the stop test within a few steps, so
a damped Gauss-Newton step scaled as SciPy's method scales it at the bounds, clipped
to them, does the job in a few dozen lines.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import coal
from grasp_torque_opt.core.geometry_contacts import collision_model
from grasp_torque_opt.core.hand import Hand
from grasp_torque_opt.core.object_geometry import coal_shape, ObjectShape
import numpy as np
import pinocchio as pin

#: Weight of the pull towards the sampled joint positions [m/rad].
PULL_JOINTS = 2e-3
#: Weight of the pull towards the sampled object position [-].
PULL_OBJECT = 2e-2
#: Weight of a contact's distance past the keep-off band of an edge [-].
EDGE_WEIGHT = 1.0
#: A contact link's mesh whose convex hull is farther than this is taken at its hull's
#: distance in the IK (more than the stop test's contact distance) [m].
APPROACH = 1e-3
#: Taken off every broad-phase bound, for coal's own tolerance [m].
BOUND_SLACK = 1e-6
#: The IK stops at a point with every contact within this share of the tolerance of
#: the surface, the other rows within this share of their slack (SurfaceIK._meets).
STOP_SHARE = 0.5
#: levenberg_marquardt's tolerances: the scaled gradient, the step (relative to x)
#: and the relative decrease of the cost it ends at (as least_squares' were).
GTOL = XTOL = FTOL = 1e-10
#: The first damping, relative to the largest diagonal entry of D J^T J D [-].
DAMPING = 3e-2


@dataclass(frozen=True)
class IKResult:
    """
    One IK's answer: the actuated joint positions, the object's position, its cost.

    ``stopped``: it ended at a point that met the stop test (:meth:`SurfaceIK.solve`);
    ``evaluations``: the residual evaluations it took.
    """

    theta: np.ndarray
    position: np.ndarray
    cost: float
    success: bool
    stopped: bool = False
    evaluations: int = 0


def _skew(r: np.ndarray) -> np.ndarray:
    """Return the matrix of r x ."""
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


class _Done(Exception):
    """Raised by the residuals at a point that already meets the stop test."""

    def __init__(self, x: np.ndarray, cost: float) -> None:
        super().__init__()
        self.x, self.cost = x, cost


def levenberg_marquardt(evaluate, x: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                        evaluations: int) -> tuple[np.ndarray, float, bool]:
    """
    Minimize 0.5 |f(x)|^2 over lower <= x <= upper from x (within the bounds).

    Each step solves (D J^T J D + mu I) h = -D J^T f and moves by s = D h, clipped to
    the bounds. D is Coleman and Li's scaling, as SciPy's trust region reflective
    method takes it: D_i = sqrt(v_i), v_i the distance to the bound that the gradient
    points x_i towards (1 where that bound is infinite), so that a variable slows as it
    nears the bound it is pushed to and stops at it. A step that lowers the cost is
    taken and mu follows Nielsen's rule; one that does not doubles its growth (Madsen,
    Nielsen and Tingleff, Methods for non-linear least squares problems, 2004, section
    3.2). Without the scaling (steps clipped to the bounds) a third more evaluations
    were needed on the bundled Allegro, and more IKs failed.

    Args:
        evaluate: x -> (f, J), the residuals and their Jacobian.
        evaluations: evaluations of ``evaluate`` at most.

    Returns:
        (x, cost, converged): converged when the scaled gradient, the step or the
        relative decrease of the cost fell below :data:`GTOL`, :data:`XTOL` or
        :data:`FTOL`; not when the evaluations ran out or the residuals or their
        Jacobian stopped being finite (the last finite point is returned).
    """
    f, J = evaluate(x)
    cost, mu, nu = 0.5 * float(f @ f), -1.0, 2.0
    for _ in range(evaluations - 1):
        g = J.T @ f
        v = np.ones_like(x)
        up, lo = (g < 0.0) & np.isfinite(upper), (g > 0.0) & np.isfinite(lower)
        v[up], v[lo] = upper[up] - x[up], x[lo] - lower[lo]
        d = np.sqrt(v)
        gh = d * g
        if np.max(np.abs(gh)) <= GTOL:
            return x, cost, True
        Jh = J * d
        A = Jh.T @ Jh
        if mu < 0.0:
            mu = DAMPING * float(A.diagonal().max())
        A.flat[::A.shape[0] + 1] += mu
        try:
            h = np.linalg.solve(A, -gh)
        except np.linalg.LinAlgError:
            h = None
        if h is None or not np.isfinite(h).all():  # not finite here: stop where it is
            return x, cost, False
        trial = np.clip(x + d * h, lower, upper)
        s = trial - x
        if math.sqrt(s @ s) <= XTOL * (math.sqrt(x @ x) + XTOL):
            return x, cost, True
        Js = J @ s
        predicted = -float(g @ s + 0.5 * (Js @ Js))
        f_new, J_new = evaluate(trial)
        new = 0.5 * float(f_new @ f_new)
        if not math.isfinite(new):  # not finite there: stop at the last finite point
            return x, cost, False
        rho = (cost - new) / predicted if predicted > 0.0 else -1.0
        if rho > 0.0:
            decrease = cost - new
            x, f, J, cost = trial, f_new, J_new, new
            mu *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
            nu = 2.0
            if decrease <= FTOL * (cost + decrease):
                return x, cost, True
        else:
            mu *= nu
            nu *= 2.0
    return x, cost, False


class SurfaceIK:
    """Every collision shape of one hand against one object: distances, Jacobians, the IK."""

    def __init__(self, hand: Hand, urdf, shape: ObjectShape, contact_links: list[str],
                 edge: float = 0.0, geom: pin.GeometryModel | None = None) -> None:
        """
        Bind the hand's collision shapes and the object once (``edge``: keep off edges).

        ``geom``: the hand's ``collision_model`` of ``urdf``, built already (its meshes
        get their convex hulls here); None: built here.
        """
        self.hand = hand
        self.shape = shape
        self.edge = edge
        self.model = hand.model
        self.data = hand.model.createData()
        self.geom = geom if geom is not None else collision_model(hand, urdf)
        self.gdata = pin.GeometryData(self.geom)
        self._owner = coal_shape(shape)  # ComputeDistance keeps a pointer: keep it alive
        self.request = coal.DistanceRequest()
        self.results = [coal.DistanceResult() for _ in self.geom.geometryObjects]
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
        # The broad phase: each shape's bounding sphere (its frame), the object's.
        self._centres, self._radii = [], []
        for g in self.geom.geometryObjects:
            g.geometry.computeLocalAABB()
            self._centres.append(np.array(g.geometry.aabb_center, dtype=float))
            self._radii.append(float(g.geometry.aabb_radius))
        self._owner.computeLocalAABB()
        self._object_centre = np.array(self._owner.aabb_center, dtype=float)
        self._object_radius = float(self._owner.aabb_radius)
        self._far = [i in self.other_shapes for i in range(len(frames))]
        self._joint = [g.parentJoint for g in self.geom.geometryObjects]
        self._hulls: dict[int, object] = {}
        self._hulls_only = False
        self._contact_hulls = any(self._hull_of(i) is not None
                                  for shapes in self.contact_shapes for i in shapes)

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

    def evaluate(self, q: np.ndarray, pose: pin.SE3, jacobians: bool = False,
                 band: float | None = None) -> list[tuple]:
        """
        Return per collision shape its distance, derivatives and nearest point.

        Each row: (signed distance [m], d(distance)/d(theta), d/d(p), the object's
        nearest point in its frame, that point's velocity columns there).

        All but the distance are None unless ``jacobians``; p is the object's position
        in the base frame; the point is taken as moving with the link. With ``band``,
        a shape of :attr:`other_shapes` whose bound (its bounding sphere's, then its
        convex hull's distance: neither exceeds its own) is at least ``band`` gets that
        bound as its distance, no derivatives (its planner row is 0 either way).
        """
        oMb, oMo, tf, centre = self._place(q, pose)
        Jb = self._jacobians() if jacobians else None
        out = []
        for i in range(len(self.computes)):
            d, exact = self._distance(i, tf, centre, band)
            if jacobians and exact:
                out.append(self._derivatives(i, d, oMb, oMo, Jb))
            else:
                out.append((d, None, None, None, None))
        return out

    def _place(self, q: np.ndarray, pose: pin.SE3) -> tuple:
        """Place the shapes at q: return the base's and the object's poses, coal's, centre."""
        pin.forwardKinematics(self.model, self.data, q)
        pin.updateGeometryPlacements(self.model, self.data, self.geom, self.gdata)
        oMb = self._base()
        oMo = oMb * pose
        return (oMb, oMo, coal.Transform3s(oMo.rotation, oMo.translation),
                oMo.act(self._object_centre))

    def _jacobians(self):
        """Compute the joint Jacobians at the placed q; return the base's (None: fixed)."""
        pin.computeJointJacobians(self.model, self.data)
        if self.base is None:
            return None
        # the base moves with q too (a hand in a robot)
        return pin.getFrameJacobian(self.model, self.data, self.base, pin.LOCAL_WORLD_ALIGNED)

    def _distance(self, i: int, tf, centre: np.ndarray, band: float | None
                  ) -> tuple[float, bool]:
        """
        Return shape i's distance and whether its coal result holds its nearest points.

        With ``band`` (the IK's), a bound stands for the distance where it says enough:
        another link's shape bounded at least ``band`` away (the bounding spheres' gap,
        then a mesh's convex hull's distance: the mesh lies in its hull) gets the bound
        and no nearest points (its row is 0 either way); a contact link's mesh whose
        hull is more than :data:`APPROACH` away, the hull's distance and points (the
        contact is at least that far). While ``_hulls_only`` (the IK's first phase)
        every mesh within the band is taken at its hull's distance.
        """
        oMg = self.gdata.oMg[i]
        res = self.results[i]
        far = band is not None and self._far[i]
        if far:
            # |a| as numpy's norm takes it (sqrt of a.a), without its dispatch
            between = oMg.act(self._centres[i]) - centre
            gap = (math.sqrt(between.dot(between)) - self._radii[i] - self._object_radius
                   - BOUND_SLACK)
            if gap >= band:
                return gap, False
        tg = coal.Transform3s(oMg.rotation, oMg.translation)  # made only when measured
        if band is not None:
            hull = self._hull_of(i)
            if hull is not None:
                res.clear()
                d = float(hull(tg, tf, self.request, res))
                if far and d - BOUND_SLACK >= band:
                    return d - BOUND_SLACK, False
                if self._hulls_only or (not far and d > APPROACH):
                    return d, True
        res.clear()
        return float(self.computes[i](tg, tf, self.request, res)), True

    def _hull_of(self, i: int):
        """Return a ComputeDistance of shape i's convex hull and the object (None: none)."""
        if i in self._hulls:
            return self._hulls[i]
        geometry = self.geom.geometryObjects[i].geometry
        compute = None
        if isinstance(geometry, coal.BVHModelBase):
            try:
                geometry.buildConvexHull(True, 'Qt')
                compute = coal.ComputeDistance(geometry.convex, self._owner)
            except (RuntimeError, ValueError):  # no hull (a flat mesh): measured always
                compute = None
        self._hulls[i] = compute
        return compute

    def _derivatives(self, i: int, d: float, oMb: pin.SE3, oMo: pin.SE3, Jb) -> tuple:
        """Return shape i's row from its last coal result (see :meth:`evaluate`)."""
        model, data, res = self.model, self.data, self.results[i]
        joint = self._joint[i]
        n = np.asarray(res.normal, dtype=float)
        n = n / max(math.sqrt(n.dot(n)), 1e-12)
        p1 = np.asarray(res.getNearestPoint1(), dtype=float)
        p2 = np.asarray(res.getNearestPoint2(), dtype=float)
        J = pin.getJointJacobian(model, data, joint, pin.LOCAL_WORLD_ALIGNED)
        r = p1 - data.oMi[joint].translation
        v = J[:3] - _skew(r) @ J[3:]  # the point's velocity columns: v - r x w
        dq = -n @ v
        if Jb is not None:  # the object's point moves with the base
            dq = dq + n @ (Jb[:3] - _skew(p2 - oMb.translation) @ Jb[3:])
        dtheta = dq[self.hand.idx_v] if self.C is None else dq @ self.C
        vtheta = v[:, self.hand.idx_v] if self.C is None else v @ self.C
        local = oMo.actInv(p2)
        return (d, dtheta, oMb.rotation.T @ n, local, oMo.rotation.T @ vtheta)

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
              max_evaluations: int = 30, tolerance: float | None = None) -> IKResult:
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
            max_evaluations: residual evaluations at most (60 before issue 36: with the
                stop test 9 in 10 kept IKs take at most 14, the IKs that fail took 33
                to 45).
            tolerance: stop at the first point that meets the stop test
                (:meth:`_meets`: every contact within :data:`STOP_SHARE` of it) [m],
                every mesh within the band measured first by its convex hull, then,
                from there, by itself; None: run to :func:`levenberg_marquardt`'s own
                tolerances, the contact meshes beyond :data:`APPROACH` by their hulls.
        """
        m = self.hand.m
        target = 1.25 * clearance  # a little more than asked: the check is strict
        stop = None if tolerance is None else STOP_SHARE * tolerance
        cache: dict = {'n': 0}

        def evaluate(x):
            cache['n'] += 1
            f, J = self._residuals(x, theta0, p0, rotation, q_base, target)
            if stop is not None and self._meets(f, stop, clearance):
                raise _Done(x.copy(), 0.5 * float(f @ f))
            return f, J

        lower = np.concatenate([bounds[0], region[0]])
        upper = np.concatenate([bounds[1], region[1]])
        x = np.clip(np.concatenate([theta0, p0]), lower, upper)
        hulls = stop is not None and self._contact_hulls
        try:
            # With contact meshes: first on the meshes' hulls (cheap), then from where
            # that stopped on the meshes themselves (most often met at once).
            for only in ((True, False) if hulls else (False,)):
                self._hulls_only = only
                try:
                    x, cost, success = levenberg_marquardt(
                        evaluate, x, lower, upper, max(max_evaluations - cache['n'], 1))
                    stopped = False
                    break
                except _Done as done:
                    x, cost, success, stopped = done.x, done.cost, True, True
        finally:
            self._hulls_only = False
        return IKResult(theta=x[:m], position=x[m:], cost=cost, success=success,
                        stopped=stopped, evaluations=cache['n'])

    def _meets(self, f: np.ndarray, stop: float, clearance: float) -> bool:
        """
        Tell whether residuals ``f`` meet the stop test (see :meth:`solve`).

        Every contact within ``stop`` of the surface; every other shape's row at most
        :data:`STOP_SHARE` of the 0.25 ``clearance`` it is asked over the clearance
        (so at least 1.125 ``clearance`` away); each edge row at most :data:`STOP_SHARE`
        of the edge (its band is twice the edge).
        """
        c = len(self.contact_links)
        pulls = c + len(self.other_shapes)
        return bool(np.all(np.abs(f[:c]) <= stop)
                    and np.all(f[c:pulls] <= STOP_SHARE * 0.25 * clearance)
                    and np.all(f[pulls + self.hand.m + 3:] <= STOP_SHARE * EDGE_WEIGHT
                               * self.edge))

    def _residuals(self, x: np.ndarray, theta0: np.ndarray, p0: np.ndarray,
                   rotation: np.ndarray, q_base: np.ndarray, target: float
                   ) -> tuple[np.ndarray, np.ndarray]:
        """
        Return the residuals and their Jacobian at x = (theta, p) (see the module).

        Far shapes are bounded, not measured (:meth:`evaluate`'s ``band``: their rows
        are 0 either way); derivatives are taken for the rows that are not 0 only.
        """
        m, c = self.hand.m, len(self.contact_links)
        theta, p = x[:m], x[m:]
        oMb, oMo, tf, centre = self._place(self.full_q(theta, q_base), pin.SE3(rotation, p))
        d = [self._distance(i, tf, centre, target)[0] for i in range(len(self.computes))]
        Jb = self._jacobians()
        f = np.zeros(c + len(self.other_shapes) + m + 3 + 2 * c)
        J = np.zeros((f.size, m + 3))
        e = f.size - 2 * c
        edges = self.edge > 0.0 and self.shape.kind in ('box', 'cylinder')
        for k, shapes in enumerate(self.contact_shapes):
            i = min(shapes, key=d.__getitem__)
            row = self._derivatives(i, d[i], oMb, oMo, Jb)
            f[k], J[k, :m], J[k, m:] = d[i], row[1], row[2]
            if edges:
                self._edge_rows(row[3], row[4], rotation, f, J, e + 2 * k)
        for k, i in enumerate(self.other_shapes, c):
            if target - d[i] > 0.0:
                row = self._derivatives(i, d[i], oMb, oMo, Jb)
                f[k], J[k, :m], J[k, m:] = target - d[i], -row[1], -row[2]
        k = c + len(self.other_shapes)
        f[k:k + m] = PULL_JOINTS * (theta - theta0)
        f[k + m:k + m + 3] = PULL_OBJECT * (p - p0)
        J[k:k + m, :m] = PULL_JOINTS * np.eye(m)
        J[k + m:k + m + 3, m:] = PULL_OBJECT * np.eye(3)
        return f, J
