# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The grasped object's geometry: its shape, the closed forms, its coal shape.

The object is a sphere, box or cylinder (the scenario's ``object`` section: axis z for
a cylinder, ``size`` as there) or a triangle mesh file (``.stl``, ``.obj``, ``.dae``,
read by coal's loader; convex or not, its surface as its triangles). Its pose is given
per call (:mod:`grasp_torque_opt.core.geometry_contacts`).

The closed forms here are the nearest point of a primitive's solid to a point ``x`` in
the object's frame, and the signed distance from it: negative inside. They serve a
spherical link (a fingertip sphere of radius r: the distance between the solids is the
centre's minus r) and the check of a contact point written by hand.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from pathlib import Path

import coal
from grasp_torque_opt.core.exceptions import cut, GeometryError, InputError, PATH_LENGTH
from grasp_torque_opt.core.scenario import ObjectSpec, SHAPES
import numpy as np
import pinocchio as pin

#: The object's kinds: the scenario's shapes and a mesh file.
KINDS = (*SHAPES, 'mesh')
#: Most triangles of a mesh object (coal's tree is built once; a distance visits a few).
MAX_MESH_TRIANGLES = 200_000


@dataclass(frozen=True)
class ObjectShape:
    """
    The object's shape, without its pose.

    Attributes:
        kind: ``sphere``, ``box``, ``cylinder`` or ``mesh``.
        size: sphere [radius], box [x, y, z] edges, cylinder [radius, length] [m]; for a
            mesh its scale per axis [-] (the file's units times this are metres).
        mesh: the mesh file (``kind == 'mesh'``), else None.
        field: the input named in errors (``object``, or the caller's).
    """

    kind: str
    size: np.ndarray
    mesh: Path | None = None
    field: str = 'object'

    @classmethod
    def from_spec(cls, spec: ObjectSpec) -> ObjectShape:
        """Return the shape of a scenario's object (its pose is ``spec.position``, ``rpy``)."""
        return cls(kind=spec.shape, size=np.asarray(spec.size, dtype=float))

    @classmethod
    def mesh_file(cls, path: str | Path, scale: float | list[float] = 1.0,
                  field: str = 'object.mesh') -> ObjectShape:
        """
        Return a mesh object: ``path`` read when bound, times ``scale`` (a number or 3).

        Raises:
            InputError: the scale is not 1 or 3 finite numbers > 0.
        """
        s = np.broadcast_to(np.asarray(scale, dtype=float), (3,)).copy() \
            if np.size(scale) in (1, 3) else np.zeros(0)
        if s.size != 3 or not np.all(np.isfinite(s) & (s > 0.0)):
            raise InputError(f'{field}.scale', f'must be 1 or 3 finite numbers > 0, got {scale!r}')
        return cls(kind='mesh', size=s, mesh=Path(path), field=field)


def object_pose(position: np.ndarray, rpy: np.ndarray | None = None) -> pin.SE3:
    """Return the pose of the object in the base frame: ``position`` [m], ``rpy`` [rad]."""
    R = np.eye(3) if rpy is None else pin.rpy.rpyToMatrix(*np.asarray(rpy, dtype=float))
    return pin.SE3(R, np.asarray(position, dtype=float))


def coal_shape(shape: ObjectShape) -> coal.CollisionGeometry:
    """
    Return the coal geometry of the object, in its own frame.

    A mesh is read, scaled and checked: a file coal cannot read, with no triangles, with
    non-finite vertices, or degenerate (flat, or of no volume) is refused.

    Raises:
        InputError: naming ``shape.field`` and what is wrong.
    """
    size = shape.size
    if shape.kind == 'sphere':
        return coal.Sphere(float(size[0]))
    if shape.kind == 'box':
        return coal.Box(*(float(v) for v in size))
    if shape.kind == 'cylinder':
        return coal.Cylinder(float(size[0]), float(size[1]))
    if shape.kind != 'mesh':
        raise InputError(f'{shape.field}.shape', f"must be one of {', '.join(KINDS)}, "
                         f'got {shape.kind!r}')
    shown = cut(shape.mesh, PATH_LENGTH)
    if not Path(shape.mesh).is_file():
        raise GeometryError(shape.field, f'mesh file not found: {shown}')
    try:
        mesh = coal.MeshLoader().load(str(shape.mesh), np.asarray(size, dtype=float))
    except (ValueError, RuntimeError) as e:
        first = str(e).split('message:')[-1].strip().splitlines()
        raise GeometryError(shape.field, f'cannot read the mesh {shown}: '
                            f"{cut(' '.join(first[:2]), 200)}") from e
    check_mesh(mesh, shape.field, shown)
    return mesh


def check_mesh(mesh: coal.BVHModelBase, field: str, shown: str) -> None:
    """
    Refuse a mesh that has no inside: no triangles, non-finite, flat or of no volume.

    Raises:
        InputError: naming ``field`` and the file ``shown``.
    """
    if mesh.num_tris == 0:
        raise GeometryError(field, f'the mesh {shown} has no triangles')
    if mesh.num_tris > MAX_MESH_TRIANGLES:
        raise GeometryError(field, f'the mesh {shown} has {mesh.num_tris} triangles, more than '
                            f'{MAX_MESH_TRIANGLES}')
    vertices = np.asarray(mesh.vertices(), dtype=float)
    if not np.all(np.isfinite(vertices)):
        raise GeometryError(field, f'the mesh {shown} has non-finite vertices')
    extent = vertices.max(axis=0) - vertices.min(axis=0)
    volume = abs(float(mesh.computeVolume()))
    if float(extent.min()) < 1e-6 or volume < 1e-6 * float(np.prod(extent)):
        raise GeometryError(field, f'the mesh {shown} is degenerate: extent '
                            f'{np.round(extent, 6).tolist()} m, volume {volume:.3g} m^3 (a '
                            'grasped object needs a solid: an inside and an outside)')


def nearest(kind: str, size: tuple[float, ...], x: float, y: float, z: float
            ) -> tuple[float, tuple[float, float, float], tuple[float, float, float]]:
    """
    Return the signed distance of a point to a primitive, its outward normal, nearest point.

    All in the object's frame, plain floats (called every cycle): distance [m], negative
    inside; the unit outward normal of the surface at the nearest point (from the
    surface towards the point when outside); the nearest surface point [m].

    Args:
        kind: ``sphere``, ``box`` or ``cylinder``.
        size: as :class:`ObjectShape`.
        x, y, z: the point in the object's frame [m].

    Raises:
        InputError: the point is the sphere's centre or on a cylinder's axis at its middle
            (no nearest face: field ``object``).
    """
    if kind == 'sphere':
        rho = math.sqrt(x * x + y * y + z * z)
        if rho < 1e-12:
            raise GeometryError('object', "a link's centre is at the sphere's centre: no "
                                'nearest surface point')
        r = size[0]
        n = (x / rho, y / rho, z / rho)
        return rho - r, n, (r * n[0], r * n[1], r * n[2])
    if kind == 'box':
        hx, hy, hz = 0.5 * size[0], 0.5 * size[1], 0.5 * size[2]
        cx, cy, cz = min(max(x, -hx), hx), min(max(y, -hy), hy), min(max(z, -hz), hz)
        dx, dy, dz = x - cx, y - cy, z - cz
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        if d > 0.0:
            return d, (dx / d, dy / d, dz / d), (cx, cy, cz)
        # Inside: the face the point is nearest to.
        depths = (hx - abs(x), hy - abs(y), hz - abs(z))
        k = depths.index(min(depths))
        p = [x, y, z]
        sign = 1.0 if p[k] >= 0.0 else -1.0
        n = [0.0, 0.0, 0.0]
        n[k] = sign
        p[k] = sign * (hx, hy, hz)[k]
        return -depths[k], tuple(n), tuple(p)
    # cylinder: [radius, length], axis z
    a, h = size[0], 0.5 * size[1]
    rho = math.sqrt(x * x + y * y)
    ux, uy = (x / rho, y / rho) if rho > 1e-12 else (1.0, 0.0)
    if rho > a or abs(z) > h:
        r = min(rho, a)
        cx, cy, cz = r * ux, r * uy, min(max(z, -h), h)
        dx, dy, dz = x - cx, y - cy, z - cz
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        return d, (dx / d, dy / d, dz / d), (cx, cy, cz)
    side, cap = a - rho, h - abs(z)
    if side <= cap:
        if rho <= 1e-12:
            raise GeometryError('object', "a link's centre is on the cylinder's axis: no "
                                'nearest surface point')
        return -side, (ux, uy, 0.0), (a * ux, a * uy, z)
    sign = 1.0 if z >= 0.0 else -1.0
    return -cap, (0.0, 0.0, sign), (x, y, sign * h)


def point_distance(shape: ObjectShape, pose: pin.SE3, point: np.ndarray) -> float:
    """
    Return the signed distance of a point (base frame) to the object's surface [m].

    Negative inside. A mesh's is coal's distance from the point to its triangles (not
    signed: a mesh has no closed form of its inside here).
    """
    local = pose.actInv(np.asarray(point, dtype=float))
    if shape.kind != 'mesh':
        return nearest(shape.kind, tuple(float(v) for v in shape.size), *local.tolist())[0]
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    tf = coal.Transform3s(np.eye(3), local)
    return float(coal.distance(coal.Sphere(1e-9), tf, coal_shape(shape), coal.Transform3s(),
                               request, result))
