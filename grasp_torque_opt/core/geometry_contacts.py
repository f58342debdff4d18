# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Contacts from geometry: the links touching the object, their points and inward normals.

Bound once (:meth:`GeometryContacts.bind`): the hand's collision shapes (the URDF's
``<collision>`` elements, through Pinocchio's GeometryModel, meshes found as the
simulation finds them), the object's shape, the candidate links and the tolerance.
Then every call (:meth:`GeometryContacts.contacts`, the node's cycle at 1 kHz) takes
the joint positions and the object's pose in the hand's base frame and returns the
contacts (docs/design.md section 4.1, "Contacts from geometry"):

- a candidate link is in contact when the signed distance between its collision shapes
  and the object is at most the tolerance (negative: they overlap);
- the contact point is the point of the link's surface nearest the object (deepest in
  it when they overlap): a material point of the link, as a contact written by hand
  is, so that J moves it with the finger; it is within the tolerance of the object's;
- the normal is the object's inward surface normal there (into the object, the
  direction the link pushes; core/inward.py's convention), base axes;
- the tangent is left to the pinned rule (core/contact_frame.py).

Only the candidate links' shapes are placed, from the joint placements
(``pin.forwardKinematics``). A spherical collision shape against a sphere, box or
cylinder object is the closed form of :func:`grasp_torque_opt.core.object_geometry.nearest`
on plain floats; any other pair is coal's distance (GJK/EPA, signed) with a
``coal.ComputeDistance`` made once per pair.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
import math
from pathlib import Path
import xml.etree.ElementTree as ET

import coal
from grasp_torque_opt.core.contact_frame import contact_rotations
from grasp_torque_opt.core.contact_links import check_contact_links
from grasp_torque_opt.core.exceptions import cut, FrameNotFound, GeometryError, InputError
from grasp_torque_opt.core.hand import (
    bounded_urdf, frame_names, Hand, MAX_URDF_BYTES, quiet_fd2)
from grasp_torque_opt.core.meshes import resolve_meshes
from grasp_torque_opt.core.object_geometry import coal_shape, nearest, ObjectShape
from grasp_torque_opt.core.resources import decode_utf8, read_bounded
from grasp_torque_opt.core.scenario import ObjectSpec
from grasp_torque_opt.core.scenario_fields import ContactSpec
import numpy as np
import pinocchio as pin

#: Default contact tolerance [m]: a link within 1 mm of the object touches it.
DEFAULT_TOLERANCE = 1e-3
#: Default deepest overlap of a link and the object [m]; deeper is an error (a wrong
#: pose, an object inside a link), not a contact.
MAX_PENETRATION = 5e-3


@dataclass(frozen=True)
class ContactSet:
    """
    The contacts found at one configuration and object pose, in candidate order.

    Attributes:
        links: the links in contact.
        frame_ids: their Pinocchio frame indices.
        points_link: the contact points in each link's frame, shape (p, 3) [m] (a
            :class:`ContactSpec`'s ``position``).
        points: the contact points in the base frame, shape (p, 3) [m]: on the link.
        object_points: the nearest points of the object's surface, base frame, (p, 3).
        normals: the inward unit normals (into the object), base axes, shape (p, 3).
        distances: the signed distances link-object, shape (p,) [m], negative overlapping.
    """

    links: tuple[str, ...]
    frame_ids: tuple[int, ...]
    points_link: np.ndarray
    points: np.ndarray
    object_points: np.ndarray
    normals: np.ndarray
    distances: np.ndarray

    @property
    def p(self) -> int:
        """Return the number of contacts."""
        return len(self.links)

    def specs(self) -> list[ContactSpec]:
        """Return the contacts as a scenario's (link, point in its frame, normal; tangent rule)."""
        return [ContactSpec(link=link, position=pt.copy(), normal=n.copy())
                for link, pt, n in zip(self.links, self.points_link, self.normals)]

    @cached_property
    def rotations(self) -> np.ndarray:
        """Return the contact frames' rotations by the pinned tangent rule, shape (p, 3, 3)."""
        return contact_rotations(self.normals, [None] * self.p,
                                 [f'contact {link}' for link in self.links])


@dataclass
class _Shape:
    """One collision shape of a link, placed by its joint."""

    joint: int
    placement: pin.SE3               # joint -> shape
    geometry: coal.CollisionGeometry
    centre: list[float] | None       # a sphere's centre in the joint frame (closed form)
    radius: float
    compute: coal.ComputeDistance | None


@dataclass
class _Link:
    name: str
    frame_id: int
    joint: int
    placement: pin.SE3               # joint -> link frame
    shapes: list[_Shape]

    def __post_init__(self) -> None:
        inverse = self.placement.inverse()  # link frame <- joint, as floats
        self.inverse_rotation = inverse.rotation.tolist()
        self.inverse_translation = inverse.translation.tolist()


def _document(urdf: str | Path, urdf_dir: Path | None) -> tuple[str, Path | None]:
    """Return the URDF document and its folder: ``urdf`` is a file or the document."""
    if isinstance(urdf, str) and urdf.lstrip().startswith('<'):
        return bounded_urdf(urdf, 'hand.urdf'), urdf_dir
    path = Path(urdf)
    text = decode_utf8(read_bounded(path, 'hand.urdf', MAX_URDF_BYTES), path, 'hand.urdf')
    return bounded_urdf(text, 'hand.urdf'), urdf_dir or path.resolve().parent


def hand_links(hand: Hand) -> set[str]:
    """
    Return the links of the hand itself within its URDF (every link when it is the hand).

    The hand is what hangs from its mount: the joint above the last joint that carries
    every actuated joint (on a G1 the fingers branch from the wrist's yaw joint, whose
    link holds the palm, so the mount is the wrist's pitch joint). Its links and every
    link beyond them are the hand: on a G1 the wrist's two last links, the palm and the
    fingers, not the arm, the torso, the legs or the other hand. Where the fingers branch
    from the URDF's root (an Allegro, a finger_edu), that is every link.
    """
    model = hand.model
    common: list[int] | None = None
    for name in hand.joints:
        chain = list(model.supports[model.getJointId(name)])
        if common is None:
            common = chain
            continue
        n = 0
        while n < min(len(common), len(chain)) and common[n] == chain[n]:
            n += 1
        common = common[:n]
    mount = model.parents[common[-1]] if common else 0
    return {f.name for f in model.frames if f.type == pin.FrameType.BODY
            and (mount == 0 or mount in model.supports[f.parentJoint])}


def collision_model(hand: Hand, urdf: str | Path, urdf_dir: Path | None = None,
                    links: set[str] | None = None) -> pin.GeometryModel:
    """
    Return the hand's collision shapes: Pinocchio's GeometryModel of the URDF.

    Args:
        hand: the hand, whose model the URDF built.
        urdf: the URDF file, or its document (e.g. ``robot_description``).
        urdf_dir: the folder relative mesh paths are in (default: the file's).
        links: only these links' shapes (their meshes alone are read: a whole robot's
            take about 1.4 s on a G1, its hand's 0.35); None: every link's.

    Raises:
        InputError: the URDF cannot be read or a mesh is not found (``hand.urdf``).
    """
    xml, folder = _document(urdf, urdf_dir)
    try:
        root = ET.fromstring(xml)
    except ET.ParseError as e:
        raise InputError('hand.urdf', f'cannot parse the URDF: {e}') from e
    if links is not None:
        for link in root.iter('link'):
            if link.get('name') not in links:
                for shape in link.findall('collision'):
                    link.remove(shape)
    resolve_meshes(root, folder)
    try:
        with quiet_fd2():  # urdfdom's own lines; the InputError below says it
            return pin.buildGeomFromUrdfString(
                hand.model, ET.tostring(root, encoding='unicode'), pin.COLLISION)
    except (RuntimeError, ValueError) as e:
        raise InputError('hand.urdf', f'cannot build the collision model: {cut(e, 400)}') from e


class GeometryContacts:
    """
    The contact model of one hand and one object: bind once, then call every cycle.

    Not shared across threads (it keeps one Pinocchio workspace and coal's results).
    """

    def __init__(self, hand: Hand, links: list[_Link], obj: ObjectShape, tolerance: float,
                 max_penetration: float) -> None:
        self.hand = hand
        self.object = obj
        self.tolerance = tolerance
        self.max_penetration = max_penetration
        self._links = links
        self._owners: tuple = ()
        self._data = hand.model.createData()
        self._size = tuple(float(v) for v in obj.size)
        self._request = coal.DistanceRequest()
        self._result = coal.DistanceResult()
        base = hand.base_link
        self._base = None if base is None else hand.model.frames[
            hand.frame_index(base, 'hand.base_link')]

    @property
    def links(self) -> tuple[str, ...]:
        """Return the candidate links, in the order contacts are returned."""
        return tuple(link.name for link in self._links)

    @property
    def closed_form(self) -> dict[str, bool]:
        """Tell per candidate link whether its every shape takes the closed form (no coal)."""
        return {link.name: all(s.centre is not None for s in link.shapes)
                for link in self._links}

    @classmethod
    def bind(cls, hand: Hand, urdf: str | Path, obj: ObjectShape | ObjectSpec,
             tolerance: float = DEFAULT_TOLERANCE, links: list[str] | None = None,
             max_penetration: float = MAX_PENETRATION, urdf_dir: Path | None = None,
             field: str = 'grasp.contacts', analytic: bool = True,
             geometry: pin.GeometryModel | None = None) -> GeometryContacts:
        """
        Build the collision shapes, the object's shape and the candidate links once.

        Args:
            hand: the hand.
            urdf: its URDF file or document (the one ``hand`` was built from).
            obj: the object's shape (a scenario's ``object``, or a mesh).
            tolerance: a link within this signed distance of the object touches it [m].
            links: the candidate links; None for every link with collision shapes that
                a joint moves (``contacts: auto``).
            max_penetration: a link deeper in the object is an error [m].
            urdf_dir: the folder of relative mesh paths in a URDF document.
            field: the input named in errors about the links.
            analytic: take the closed form where it applies (False: coal for every pair,
                the independent formulation the tests compare with).
            geometry: the hand's :func:`collision_model` of ``urdf``, built already
                (its shapes are used, not copied); None: built here.

        Raises:
            InputError: a bad tolerance, URDF or object; FrameNotFound: an unknown link;
            GeometryError: a candidate link without collision shapes, a degenerate mesh.
        """
        for name, value in (('tolerance', tolerance), ('max_penetration', max_penetration)):
            if not (math.isfinite(value) and value > 0.0):
                raise InputError(name, f'must be finite and > 0 [m], got {value!r}')
        shape = ObjectShape.from_spec(obj) if isinstance(obj, ObjectSpec) else obj
        target = coal_shape(shape)
        model = hand.model
        if geometry is None:  # the candidate links' meshes alone when they are named
            geometry = collision_model(hand, urdf, urdf_dir,
                                       None if links is None else set(links))
        by_link: dict[str, list] = {}
        for g in geometry.geometryObjects:
            by_link.setdefault(model.frames[g.parentFrame].name, []).append(g)
        if links is None:
            names = [n for n in frame_names(model) if n in by_link and moved_by_joint(hand, n)]
        else:
            names = list(links)
            for i, name in enumerate(names):
                if not model.existFrame(name):
                    raise FrameNotFound(f'{field}[{i}].link', name, frame_names(model))
            check_contact_links(model, names, field, hand.base_link)
            for i, name in enumerate(names):
                if name not in by_link:
                    raise GeometryError(f'{field}[{i}].link', f"link '{cut(name)}' has no "
                                        'collision geometry in the URDF: its contact cannot '
                                        'be found from geometry (give its position)')
        closed = analytic and shape.kind != 'mesh'
        out = []
        for name in names:
            fid = model.getFrameId(name)
            frame = model.frames[fid]
            shapes = []
            for g in by_link[name]:
                sphere = isinstance(g.geometry, coal.Sphere) and closed
                shapes.append(_Shape(
                    joint=g.parentJoint, placement=g.placement.copy(), geometry=g.geometry,
                    centre=g.placement.translation.tolist() if sphere else None,
                    radius=float(g.geometry.radius) if sphere else 0.0,
                    compute=None if sphere else coal.ComputeDistance(g.geometry, target)))
            out.append(_Link(name, fid, frame.parentJoint, frame.placement.copy(), shapes))
        bound = cls(hand, out, shape, float(tolerance), float(max_penetration))
        # coal's ComputeDistance keeps pointers to both shapes: keep their owners alive.
        bound._owners = (geometry, target)
        return bound

    def contacts(self, q: np.ndarray, object_pose: pin.SE3,
                 tolerance: float | None = None) -> ContactSet:
        """
        Return the contacts at joint positions ``q`` and the object's pose.

        Args:
            q: the full configuration, shape (model.nq,) (``Hand.complete`` applied).
            object_pose: the object's frame in the hand's base frame.
            tolerance: this call's tolerance [m] instead of the bound one (a caller's
                hysteresis: a larger one for the links already in contact).

        Raises:
            GeometryError: a link deeper in the object than ``max_penetration``, its
                centre inside the object, or the object's centre inside a spherical link.
        """
        tol = self.tolerance if tolerance is None else tolerance
        found = [r for r in self._evaluate(q, object_pose) if r[1] <= tol]
        p = len(found)
        if p == 0:
            empty = np.empty((0, 3))
            return ContactSet((), (), empty, empty, empty, empty, np.empty(0))
        pts = np.array([r[2:6] for r in found], dtype=float).reshape(p, 4, 3)
        points, opoints, normals = pts[:, 0], pts[:, 1], pts[:, 2]
        if self._base is not None:  # world -> base frame
            oMb = self._data.oMi[self._base.parentJoint] * self._base.placement
            Rb, tb = oMb.rotation, oMb.translation
            points, opoints, normals = (points - tb) @ Rb, (opoints - tb) @ Rb, normals @ Rb
        return ContactSet(links=tuple(r[0].name for r in found),
                          frame_ids=tuple(r[0].frame_id for r in found),
                          points_link=pts[:, 3], points=points, object_points=opoints,
                          normals=normals, distances=np.array([r[1] for r in found]))

    def distances(self, q: np.ndarray, object_pose: pin.SE3) -> dict[str, float]:
        """Return every candidate link's signed distance to the object [m]."""
        return {r[0].name: r[1] for r in self._evaluate(q, object_pose)}

    def _evaluate(self, q: np.ndarray, object_pose: pin.SE3) -> list[tuple]:
        """
        Per candidate link: (link, distance, point, object point, normal, point in link).

        World frame but the last (the link's frame), plain sequences of 3 floats.
        """
        model, data = self.hand.model, self._data
        pin.forwardKinematics(model, data, q)
        oMo = object_pose
        if self._base is not None:
            oMo = data.oMi[self._base.parentJoint] * self._base.placement * object_pose
        R = oMo.rotation
        rows = R.tolist()
        t = oMo.translation.tolist()
        tf = None
        out = []
        for link in self._links:
            best = None
            for s in link.shapes:
                oMi = data.oMi[s.joint]
                if s.centre is not None:
                    r = self._sphere(link, s, oMi.rotation.tolist(), oMi.translation.tolist(),
                                     rows, t)
                else:
                    if tf is None:
                        tf = coal.Transform3s(R, oMo.translation)
                    r = self._coal(link, s, oMi, tf)
                if best is None or r[1] < best[1]:
                    best = r
            if best[1] < -self.max_penetration:
                raise GeometryError('object', f"link '{link.name}' is {-1e3 * best[1]:.3g} mm "
                                    f'inside the object, more than {1e3 * self.max_penetration:g}'
                                    ' mm: the object pose or the joint positions are wrong')
            out.append(best)
        return out

    def _sphere(self, link: _Link, s: _Shape, Ri: list[list[float]], ti: list[float],
                R: list[list[float]], t: list[float]) -> tuple:
        """Return a spherical shape's row by the closed form (plain floats)."""
        radius = s.radius
        (a, b, e), (f, g, h), (k, m, n) = Ri
        cx, cy, cz = s.centre
        c = (ti[0] + a * cx + b * cy + e * cz, ti[1] + f * cx + g * cy + h * cz,
             ti[2] + k * cx + m * cy + n * cz)
        dx, dy, dz = c[0] - t[0], c[1] - t[1], c[2] - t[2]
        (oa, ob, oe), (of, og, oh), (ok, om, on) = R
        x = oa * dx + of * dy + ok * dz
        y = ob * dx + og * dy + om * dz
        z = oe * dx + oh * dy + on * dz
        if self.object.kind == 'sphere' and x * x + y * y + z * z < radius * radius:
            raise GeometryError('object', f"the object's centre is inside link "
                                f"'{link.name}': the object pose or the joint positions are "
                                'wrong')
        dc, (ux, uy, uz), (px, py, pz) = nearest(self.object.kind, self._size, x, y, z)
        if dc < 0.0:
            raise GeometryError('object', f"the centre of link '{link.name}''s sphere is "
                                'inside the object: the object pose or the joint positions '
                                'are wrong')
        # Outward normal and nearest point back to the world; inward = -outward.
        nx = oa * ux + ob * uy + oe * uz
        ny = of * ux + og * uy + oh * uz
        nz = ok * ux + om * uy + on * uz
        obj = (t[0] + oa * px + ob * py + oe * pz, t[1] + of * px + og * py + oh * pz,
               t[2] + ok * px + om * py + on * pz)
        point = (c[0] - radius * nx, c[1] - radius * ny, c[2] - radius * nz)
        # The point in the joint's frame (its centre there, minus r along n in its axes),
        # then in the link's.
        jx = cx - radius * (a * nx + f * ny + k * nz)
        jy = cy - radius * (b * nx + g * ny + m * nz)
        jz = cz - radius * (e * nx + h * ny + n * nz)
        (fa, fb, fe), (ff, fg, fh), (fk, fm, fn) = link.inverse_rotation
        ft = link.inverse_translation
        local = (ft[0] + fa * jx + fb * jy + fe * jz, ft[1] + ff * jx + fg * jy + fh * jz,
                 ft[2] + fk * jx + fm * jy + fn * jz)
        return link, dc - radius, point, obj, (-nx, -ny, -nz), local

    def _coal(self, link: _Link, s: _Shape, oMi: pin.SE3, tf_object: coal.Transform3s
              ) -> tuple:
        """Return a shape's row by coal's signed distance (link first: normal into the object)."""
        oMg = oMi * s.placement
        res = self._result
        res.clear()
        d = s.compute(coal.Transform3s(oMg.rotation, oMg.translation), tf_object,
                      self._request, res)
        normal = np.asarray(res.normal, dtype=float)
        norm = float(np.linalg.norm(normal))
        if not (math.isfinite(d) and norm > 0.5):
            raise GeometryError('object', f"coal found no distance between link '{link.name}' "
                                f'and the object ({d!r})')
        point = res.getNearestPoint1()
        local = (oMi * link.placement).actInv(point)
        return link, float(d), point, res.getNearestPoint2(), normal / norm, local


def moved_by_joint(hand: Hand, name: str) -> bool:
    """Tell whether a joint moves link ``name`` (relative to the base): it can push."""
    try:
        check_contact_links(hand.model, [name], base=hand.base_link)
    except InputError:
        return False
    return True
