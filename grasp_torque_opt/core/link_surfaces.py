# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
How far a point is from a link's own surface: the URDF's collision shapes of each link.

Bound once from the URDF (:func:`grasp_torque_opt.core.geometry_contacts.collision_model`,
Pinocchio's GeometryModel of its ``<collision>`` elements); then
:meth:`LinkSurfaces.distances` gives, for points each said to lie on a named link, their
distance to that link's nearest shape, placed at the joint placements of a Pinocchio data
(``data.oMi``) the caller has computed. A sphere and a box take the closed form; any
other shape (mesh, cylinder, capsule) coal's signed distance to a point-sized sphere.
A link without collision shapes has no surface here (:meth:`LinkSurfaces.has`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import coal
from grasp_torque_opt.core.geometry_contacts import collision_model, moved_by_joint
from grasp_torque_opt.core.hand import frame_names, Hand
import numpy as np
import pinocchio as pin

#: The radius of the sphere that stands for a point in coal's distance [m].
POINT_RADIUS = 1e-9


@dataclass
class _Shape:
    """One collision shape: its joint, its placement there, and how it is measured."""

    joint: int
    placement: pin.SE3                # joint -> shape
    geometry: coal.CollisionGeometry
    kind: str                         # 'sphere', 'box' (closed forms) or 'coal'
    size: np.ndarray                  # the radius, or the box's half sides [m]


class LinkSurfaces:
    """
    The collision shapes of a hand's links, by link frame name.

    Args:
        shapes: link frame name -> its shapes (those the URDF attaches to that frame).
    """

    def __init__(self, shapes: dict[str, list[_Shape]]) -> None:
        self._shapes = shapes
        self._point = coal.Sphere(POINT_RADIUS)
        self._request = coal.DistanceRequest()
        self._result = coal.DistanceResult()

    @classmethod
    def bind(cls, hand: Hand, urdf: str | Path, urdf_dir: Path | None = None) -> LinkSurfaces:
        """
        Read the collision shapes of the URDF ``hand`` was built from.

        Raises:
            InputError: the URDF cannot be read or a mesh is not found (``hand.urdf``).
        """
        geom = collision_model(hand, urdf, urdf_dir)
        frames = hand.model.frames
        shapes: dict[str, list[_Shape]] = {}
        for g in geom.geometryObjects:
            shape = g.geometry
            if isinstance(shape, coal.Sphere):
                kind, size = 'sphere', np.array([shape.radius])
            elif isinstance(shape, coal.Box):
                kind, size = 'box', np.array(shape.halfSide, dtype=float)
            else:
                kind, size = 'coal', np.zeros(0)
            shapes.setdefault(frames[g.parentFrame].name, []).append(
                _Shape(g.parentJoint, g.placement.copy(), shape, kind, size))
        bound = cls(shapes)
        bound._owner = geom  # the shapes' owner stays alive with them
        return bound

    @property
    def links(self) -> tuple[str, ...]:
        """Return the link frames that have collision shapes."""
        return tuple(self._shapes)

    def bare(self, hand: Hand) -> list[str]:
        """Return the links a joint moves (those that can push) without collision shapes."""
        names = [f.name for f in hand.model.frames
                 if f.type == pin.FrameType.BODY and f.name not in self._shapes]
        return [n for n in frame_names(hand.model) if n in set(names) and moved_by_joint(hand, n)]

    def has(self, link: str) -> bool:
        """Tell whether ``link`` has collision shapes (a surface to check against)."""
        return link in self._shapes

    def distances(self, data: pin.Data, links: tuple[str, ...], points: np.ndarray
                  ) -> np.ndarray:
        """
        Give each point's distance to its own link's surface [m] (NaN: the link has none).

        Args:
            data: a Pinocchio data of the hand's model, its joint placements ``oMi`` at the
                configuration of the moment.
            links: each point's link frame.
            points: the points in the world frame of ``data``, shape (p, 3) [m].

        Returns:
            |signed distance| to the nearest of the link's shapes, shape (p,): 0 on the
            surface, positive off it or inside it.
        """
        out = np.full(len(links), np.nan)
        for i, (link, point) in enumerate(zip(links, points)):
            shapes = self._shapes.get(link)
            if shapes:
                out[i] = min(abs(self._signed(s, data.oMi[s.joint] * s.placement, point))
                             for s in shapes)
        return out

    def _signed(self, s: _Shape, oMs: pin.SE3, point: np.ndarray) -> float:
        """Return a point's signed distance to one placed shape [m] (negative inside)."""
        local = oMs.actInv(point)
        if s.kind == 'sphere':
            return float(np.linalg.norm(local)) - float(s.size[0])
        if s.kind == 'box':
            d = np.abs(local) - s.size
            return float(np.linalg.norm(np.maximum(d, 0.0))) + min(float(d.max()), 0.0)
        res = self._result
        res.clear()
        d = coal.distance(s.geometry, coal.Transform3s(oMs.rotation, oMs.translation),
                          self._point, coal.Transform3s(np.eye(3), point), self._request, res)
        return float(d) + POINT_RADIUS
