# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The cycle's contacts from geometry, and the object's pose they are found at.

With ``contact_geometry.enabled`` (docs/node.md, "Contacts from geometry"), each cycle
finds the contacts from the joint positions and the object's pose
(:class:`~grasp_torque_opt.core.geometry_contacts.GeometryContacts`, bound once at
configure time), so a rolling tip's point and normal move with it, and the set of links
in contact may change from one cycle to the next. The rules:

- hysteresis: a link enters the set when its signed distance to the object is at most
  ``tolerance``; a link in the set leaves it only beyond ``release`` times that (a tip
  dithering at the tolerance does not flip the set every cycle);
- each cycle's command is solved with that cycle's set only: a contact that is gone is
  never in a command (the rate rule does not step between two different sets,
  ``TorqueController._slew``);
- a change of the set is counted (``changes``) and its links shown on /diagnostics;
- no link within the tolerance: no grasp, a fault.

The object's pose (the ``object_pose`` input, else the scenario's held fixed in the
hand's base frame) moves the object origin and the load's point with it
(:func:`moved_origin`). A pose is refused beyond ``object_pose.max_offset`` of the
scenario's, or beyond ``uncertainty.pose`` of where the fingertips place the object
(:func:`pose_in_base`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from grasp_torque_opt.control.checks import finite, quaternion_matrix, show
from grasp_torque_opt.control.plausible import pose_tolerance
from grasp_torque_opt.core.exceptions import GeometryError, InputError
from grasp_torque_opt.core.geometry_contacts import ContactSet, GeometryContacts
from grasp_torque_opt.core.object_from_hand import ObjectEstimate
from grasp_torque_opt.core.object_geometry import object_pose
from grasp_torque_opt.core.scenario import ObjectSpec
from grasp_torque_opt.core.scenario_fields import ContactSpec
import numpy as np
import pinocchio as pin


@dataclass(frozen=True)
class ObjectPose:
    """
    An object pose as received: the object's frame in model frame ``frame``.

    Attributes:
        frame: model frame ('' = the base frame; a frame tf2 resolved is given here in
            the base frame already).
        pose: the object's frame in ``frame``.
    """

    frame: str
    pose: pin.SE3


class ContactTracker:
    """
    The contact set of the cycle, found from geometry with hysteresis.

    Args:
        model: the bound contact model (its tolerance is the entering one).
        obj: the scenario's object (its pose is the one held without an input).

    Attributes:
        links: the links in contact at the last update.
        changes: how many times the set changed (the first set is not a change).
        last: the last contact set found (None before the first).
    """

    def __init__(self, model: GeometryContacts, obj: ObjectSpec) -> None:
        self.model = model
        self.scenario_pose = object_pose(obj.position, obj.rpy)
        self.links: tuple[str, ...] | None = None
        self.changes = 0
        self.last: ContactSet | None = None

    def update(self, q: np.ndarray, pose: pin.SE3, release: float) -> list[ContactSpec]:
        """
        Find this cycle's contacts: enter at the tolerance, leave beyond ``release`` times it.

        Args:
            q: the full configuration (coupled joints completed).
            pose: the object's frame in the hand's base frame.
            release: the leaving distance, in tolerances (>= 1).

        Returns:
            The contacts, in the candidate links' order (tangent by the pinned rule).

        Raises:
            InputError: no link within the tolerance (field ``contact_geometry``); a link
                deeper in the object than the model's ``max_penetration``.
        """
        tol = self.model.tolerance
        try:
            found = self.model.contacts(q, pose, tolerance=tol * release)
        except GeometryError as e:
            raise InputError('object_pose', f'contacts from geometry: {e}') from e
        held = self.links or ()
        keep = [i for i, (link, d) in enumerate(zip(found.links, found.distances))
                if d <= tol or link in held]
        if len(keep) != found.p:
            found = subset(found, keep)
        if found.links != self.links:
            if self.links is not None:
                self.changes += 1
            self.links = found.links
        self.last = found
        if found.p == 0:
            raise InputError('contact_geometry', 'no candidate link within '
                             f'contact_geometry.tolerance ({1e3 * tol:g} mm) of the object: '
                             'nothing holds it')
        return found.specs()


def subset(found: ContactSet, keep: list[int]) -> ContactSet:
    """Return the contacts ``keep`` of a contact set (in its order)."""
    k = np.asarray(keep, dtype=int)
    return ContactSet(links=tuple(found.links[i] for i in keep),
                      frame_ids=tuple(found.frame_ids[i] for i in keep),
                      points_link=found.points_link[k], points=found.points[k],
                      object_points=found.object_points[k], normals=found.normals[k],
                      distances=found.distances[k])


def offset_limit(config) -> float:
    """Return ``object_pose.max_offset`` in use [m]: 0 follows the stated pose uncertainty."""
    return config.object_pose_max_offset or pose_tolerance(config)


def pose_in_base(received: ObjectPose | None, scenario: pin.SE3, placements,
                 config, fingertips: ObjectEstimate | None = None) -> pin.SE3:
    """
    Give the object's pose in the base frame, checked against the scenario's and the hand's.

    Args:
        received: the input's pose (None: the scenario's, held fixed in the base frame).
        scenario: the scenario's pose in the base frame.
        placements: ``frame -> SE3`` of a model frame in the base frame, at the joint
            state of the moment.
        config: ``object_pose_max_offset`` and ``uncertainty_pose`` [m].
        fingertips: where the fingertips place the object at that joint state
            (:class:`~grasp_torque_opt.core.object_from_hand.ObjectFromHand`), or None.

    Raises:
        InputError: ``object_pose.pose.position`` farther than ``object_pose.max_offset``
            from the scenario's, or than ``uncertainty.pose`` from the fingertips'.
    """
    if received is None:
        return scenario
    pose = received.pose if not received.frame else placements(received.frame) * received.pose
    limit = offset_limit(config)
    offset = float(np.linalg.norm(pose.translation - scenario.translation))
    if not offset <= limit:  # NaN too
        raise InputError('object_pose.pose.position', f'is {1e3 * offset:.4g} mm from the '
                         f"scenario's object position (base frame), beyond "
                         f'object_pose.max_offset ({1e3 * limit:g} mm)')
    if fingertips is not None:
        tol = pose_tolerance(config)
        off = float(np.linalg.norm(pose.translation - fingertips.pose.translation))
        if not off <= tol:
            raise InputError('object_pose.pose.position', f'is {1e3 * off:.4g} mm from where '
                             'the fingertips place the object (their kinematics since the '
                             f"grasp's start), beyond uncertainty.pose ({1e3 * tol:g} mm)")
    return pose


def placements_at(hand, q: np.ndarray, kinematics: bool = True):
    """
    Give ``frame -> SE3``: a model frame in the grasp's base frame, at ``q``.

    ``kinematics``: place the frames at ``q`` in the hand's data first (False: the data
    holds them already, as in the cycle).
    """
    model, data = hand.model, hand.data
    if kinematics:
        if hand.coupling.mimics:
            q = hand.complete(q.copy())
        pin.framesForwardKinematics(model, data, q)
    base = None if hand.base_link is None else model.getFrameId(hand.base_link)

    def placement(frame: str) -> pin.SE3:
        oMf = data.oMf[model.getFrameId(frame)]
        return oMf if base is None else data.oMf[base].actInv(oMf)
    return placement


def moved_origin(origin: np.ndarray, scenario: pin.SE3, pose: pin.SE3) -> np.ndarray:
    """Give the object origin carried from the scenario's pose to ``pose`` (base frame)."""
    return pose.act(scenario.actInv(np.asarray(origin, dtype=float)))


def moved_object(obj: ObjectSpec, pose: pin.SE3) -> ObjectSpec:
    """Give the scenario's object at ``pose``: its centre (the load's point) moved there."""
    return dataclasses.replace(obj, position=pose.translation.copy(),
                               rpy=pin.rpy.matrixToRpy(pose.rotation))


def geometry_of(cycle, inputs, q: np.ndarray) -> tuple[list[ContactSpec], np.ndarray, Any]:
    """
    Give a cycle's contacts, object origin and the load's object (None: the scenario's).

    The object pose in use (:func:`pose_in_base`; the hand's data placed at ``q``) moves
    the origin and the object; the tracker (when bound, and no contacts were received)
    finds the contacts at ``q`` and that pose, else the scenario's are given.

    Args:
        cycle: the :class:`~grasp_torque_opt.control.cycle.Cycle` (its setup, config,
            tracker, object and scenario pose).
        inputs: the snapshot of inputs.
        q: the full configuration the hand's data is placed at.
    """
    setup = cycle.setup
    contacts, origin, at = setup.contacts, setup.object_origin, None
    pose = cycle.scenario_pose
    if inputs.object_pose is not None:
        tips = None if cycle.hand_object is None else cycle.hand_object.estimate(q)
        pose = pose_in_base(inputs.object_pose, pose, placements_at(setup.hand, q, False),
                            cycle.config, tips)
        origin = moved_origin(origin, cycle.scenario_pose, pose)
        at = (moved_object(cycle.object, pose), origin)
    cycle.pose_in_use = pose
    if inputs.contacts is None and cycle.tracker is not None:
        contacts = cycle.tracker.update(q, pose, cycle.config.contact_release)
    return contacts, origin, at


def checked_pose(hand, frame: str, position: np.ndarray, quaternion: np.ndarray,
                 transform: tuple[np.ndarray, np.ndarray] | None, unresolved: str):
    """
    Check an object pose and return it (:class:`~grasp_torque_opt.control.geometry.ObjectPose`).

    Args:
        hand: the hand (its model's frames, its base frame).
        frame: '' or the base frame, a model frame, or another frame with ``transform``.
        position: [m], shape (3,).
        quaternion: (x, y, z, w), shape (4,).
        transform: ``frame``'s rotation and origin in the base frame (tf2), or None.
        unresolved: why ``frame`` could not be looked up (for the message).

    Raises:
        InputError: not finite, a non-unit quaternion, a frame neither in the model nor
            transformed.
    """
    p = finite(position, 'object_pose.pose.position')
    R = quaternion_matrix(np.asarray(quaternion, dtype=float), 'object_pose.pose.orientation')
    pose = pin.SE3(R, p)
    if frame in ('', hand.base_frame):
        return ObjectPose('', pose)
    if hand.model.existFrame(frame):
        return ObjectPose(frame, pose)
    if transform is None:
        raise InputError('object_pose.header.frame_id', f"'{show(frame)}' is neither a frame "
                         f'of the hand nor transformed to its base frame ({unresolved})')
    R_t, p_t = (finite(v, 'object_pose.header.frame_id transform') for v in transform)
    return ObjectPose('', pin.SE3(R_t, p_t) * pose)
