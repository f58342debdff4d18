# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Whether estimated contacts can be the grasp's: on their own links, pushing into the object.

A well-formed lie on ``contacts`` was certified before: four flipped normals (a
perception sign bug) gave commands that pull; swapped fingertips put contacts 71 to
95 mm from their own links, and index and middle tips named the other way round 33.6 mm,
within the 50 mm of the frame rule (docs/node.md, "Contacts and object pose against the
hand"). The rules, in the base frame at the configuration of the moment:

- a contact point at most ``max_contact_surface_distance`` from its own link's surface
  (the URDF's collision shapes of that link, :class:`~grasp_torque_opt.core.link_surfaces.
  LinkSurfaces`); on a link without collision shapes, at most ``max_contact_link_distance``
  from its frame (the node warns once at configure time which links those are);
- with the scenario's object, at most ``uncertainty.pose`` (at least 1 mm) plus
  ``max_contact_surface_distance`` off the object's surface at the pose in use;
- its normal points into the object (:func:`grasp_torque_opt.core.inward.check_inward_normals`:
  towards the object origin, and into the scenario object's surface where it has one);
- a contact's link is not the root, a frame fixed to the root, nor a joint frame
  (:func:`grasp_torque_opt.core.contact_links.check_contact_links`, when the scenario
  is bound).
"""

from __future__ import annotations

from dataclasses import dataclass

from grasp_torque_opt.core.exceptions import GeometryError, InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.inward import check_inward_normals
from grasp_torque_opt.core.link_surfaces import LinkSurfaces
from grasp_torque_opt.core.object_geometry import ObjectShape, point_distance
from grasp_torque_opt.core.scenario import ObjectSpec
import numpy as np
import pinocchio as pin

#: The least pose tolerance [m] when none is stated (uncertainty.pose 0): the fingers'
#: own kinematic error, 0.01 rad of joint reading over 0.1 m of finger.
MIN_POSE_TOLERANCE = 1e-3


def pose_tolerance(config) -> float:
    """Return the stated pose uncertainty in use [m]: ``uncertainty.pose``, at least 1 mm."""
    return max(config.uncertainty_pose, MIN_POSE_TOLERANCE)


@dataclass(frozen=True)
class Placed:
    """
    Contact points placed at a configuration, with what the surface rules need.

    Attributes:
        points: the points in the grasp's base frame, shape (p, 3) [m].
        links: each point's link.
        data: the hand's Pinocchio data, its placements at that configuration.
        base: the base link's placement in the world of ``data`` (None: the root's).
        origins: the links' frame origins in the base frame, shape (p, 3) [m].
    """

    points: np.ndarray
    links: tuple[str, ...]
    data: pin.Data
    base: pin.SE3 | None
    origins: np.ndarray


def check_surfaces(placed: Placed, surfaces: LinkSurfaces | None, config,
                   obj: ObjectSpec | None = None, pose: pin.SE3 | None = None) -> None:
    """
    Refuse a contact point off its own link's surface, or off the object's.

    Args:
        placed: the points and their links, placed.
        surfaces: the links' collision shapes (None: none could be read; the frame rule
            for every link).
        config: ``max_contact_surface_distance``, ``max_contact_link_distance`` and
            ``uncertainty_pose`` [m].
        obj: the scenario's object (None: no object rule).
        pose: the object's frame in the base frame (the pose in use).

    Raises:
        InputError: ``contacts.poses[i].position``, naming the link and the distance.
    """
    links = placed.links
    shaped = [surfaces is not None and surfaces.has(link) for link in links]
    if not all(shaped):  # links without collision shapes: the frame rule
        free = [i for i, s in enumerate(shaped) if not s]
        check_on_links(placed.points[free], placed.origins[free],
                       tuple(links[i] for i in free), config.max_contact_link_distance,
                       free)
    limit = config.max_contact_surface_distance
    if any(shaped):
        world = placed.points if placed.base is None else \
            placed.points @ placed.base.rotation.T + placed.base.translation
        d = surfaces.distances(placed.data, links, world)
        bad = np.array(shaped) & ~(d <= limit)
        if bad.any():
            i = int(np.argmax(bad))
            raise InputError(f'contacts.poses[{i}].position', f'is {1e3 * d[i]:.3g} mm from '
                             f"the surface of its link '{links[i]}' (its collision geometry),"
                             f' beyond max_contact_surface_distance ({1e3 * limit:g} mm): a '
                             'contact of another finger or link, or a wrong frame')
    if obj is not None and pose is not None:
        check_on_object(placed.points, links, obj, pose, pose_tolerance(config) + limit)


def check_on_object(points: np.ndarray, links: tuple[str, ...], obj: ObjectSpec,
                    pose: pin.SE3, limit: float) -> None:
    """
    Refuse a contact point farther than ``limit`` off the object's surface (or inside it).

    Raises:
        InputError: ``contacts.poses[i].position``.
    """
    shape = ObjectShape.from_spec(obj)
    for i, p in enumerate(points):
        try:
            d = abs(point_distance(shape, pose, p))
        except GeometryError:  # at a sphere's centre: a radius off its surface
            d = float(np.max(shape.size))
        if not d <= limit:
            raise InputError(f'contacts.poses[{i}].position', f"(on '{links[i]}') is "
                             f"{1e3 * d:.3g} mm off the object's surface at the pose in use, "
                             f'beyond uncertainty.pose + max_contact_surface_distance '
                             f'({1e3 * limit:g} mm): the contact cannot touch the object')


def check_contacts(setup: GraspSetup, obj: ObjectSpec | None, q: np.ndarray, frame: str,
                   positions: np.ndarray, rotations: np.ndarray, config,
                   links: tuple[str, ...] | None = None, surfaces: LinkSurfaces | None = None,
                   pose: pin.SE3 | None = None) -> None:
    """
    Check contact poses at configuration ``q``: on their own links, pushing into the object.

    Args:
        setup: the grasp (its hand's model and data, its contacts' links, object origin).
        obj: the scenario's object, or None.
        q: the configuration the links are placed at.
        frame: model frame of the poses ('' = the base frame).
        positions: contact points, shape (p, 3) [m].
        rotations: contact frame axes, shape (p, 3, 3).
        config: the limits (:func:`check_surfaces`).
        links: each pose's link (None: the scenario's contacts', by index).
        surfaces: the links' collision shapes (None: the frame rule for every link).
        pose: the object's frame in the base frame, in use at ``q`` (None: no object rule).

    Raises:
        InputError: naming the contact (:func:`check_surfaces`, :func:`check_inward`).
    """
    hand = setup.hand
    model, data = hand.model, hand.data
    if hand.coupling.mimics:  # coupled joints follow their actuators, as in the cycle
        q = hand.complete(q.copy())
    pin.framesForwardKinematics(model, data, q)
    # In the grasp's base frame (the base link's, in a robot), as the cycle places them.
    base = data.oMf[model.getFrameId(hand.base_link)] if hand.base_link is not None else None
    oMF = data.oMf[model.getFrameId(frame or hand.base_frame)]
    oMF = base.actInv(oMF) if base is not None else oMF
    R = oMF.rotation
    points, normals = positions @ R.T + oMF.translation, rotations[:, :, 2] @ R.T
    links = links or tuple(c.link for c in setup.contacts)
    placements = [data.oMf[model.getFrameId(link)] for link in links]
    origins = np.array([(base.actInv(m) if base is not None else m).translation
                        for m in placements])
    check_surfaces(Placed(points, links, data, base, origins), surfaces, config, obj, pose)
    check_inward(points, normals, links, setup.object_origin, obj)


def check_on_links(points: np.ndarray, link_origins: np.ndarray, links: tuple[str, ...],
                   limit: float, indices: list[int] | None = None) -> None:
    """
    Refuse a contact point farther than ``limit`` from its own link's frame.

    Args:
        points: contact points, base frame, shape (p, 3) [m].
        link_origins: their links' frame origins, base frame, shape (p, 3) [m].
        links: the links' names, for the message.
        limit: ``max_contact_link_distance`` [m].
        indices: each point's index in the message (None: 0, 1, ...).

    Raises:
        InputError: ``contacts.poses[i].position``.
    """
    d = np.linalg.norm(points - link_origins, axis=1)
    if (d <= limit).all():  # False for NaN as well
        return
    i = int(np.argmax(np.where(np.isnan(d), np.inf, d)))
    k = i if indices is None else indices[i]
    raise InputError(f'contacts.poses[{k}].position', f'is {d[i]:.4g} m from its link '
                     f"'{links[i]}', beyond max_contact_link_distance ({limit} m): a "
                     'contact of another finger, or a wrong frame')


def check_inward(points: np.ndarray, normals: np.ndarray, links: tuple[str, ...],
                 origin: np.ndarray, obj: ObjectSpec | None) -> None:
    """
    Refuse a contact whose normal points out of the object (the scenario's rule).

    Raises:
        InputError: ``contacts.poses[i].orientation``, with the scenario check's words.
    """
    try:
        check_inward_normals(points, normals, links, origin, obj)
    except InputError as e:
        i = e.field[len('grasp.contacts['):].split(']')[0]
        raise InputError(f'contacts.poses[{i}].orientation', e.problem) from e


def points_inward(points: np.ndarray, normals: np.ndarray, origin: np.ndarray) -> int:
    """
    Return the first contact whose normal points away from the object origin, or -1.

    The cheap half of :func:`check_inward`, for every cycle (vectorized).
    """
    bad = np.einsum('ij,ij->i', normals, origin - points) < 0.0
    return int(np.argmax(bad)) if bad.any() else -1
