# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Contact estimates (geometry_msgs/PoseArray): one pose per scenario contact, or per link.

``header.frame_id`` is ``FRAME`` (one pose per scenario contact, by index) or
``FRAME;LINK_1,...,LINK_n`` (one pose per named link, in order:
:mod:`grasp_torque_opt.control.named_contacts`). Each pose is checked plausible at the
latest joint state (:func:`grasp_torque_opt.control.plausible.check_contacts`: on their
own links' surfaces, on the object's, pushing into it); the cycle checks them again where
the frame is placed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from grasp_torque_opt.control.checks import contact_rotations
from grasp_torque_opt.control.geometry import placements_at
from grasp_torque_opt.control.inputs.base import aged, latest_q
from grasp_torque_opt.control.named_contacts import named_frame, split_frame_id
from grasp_torque_opt.control.plausible import check_contacts
import numpy as np
import pinocchio as pin


def pose_in_use(store, q: np.ndarray) -> pin.SE3 | None:
    """Give the object's frame in the base frame at ``q``: the input's, else the scenario's."""
    got = store.inputs.object_pose
    if got is None or store.scenario_pose is None:
        return store.scenario_pose
    return got.pose if not got.frame else placements_at(store.setup.hand, q)(got.frame) * got.pose


@dataclass(frozen=True)
class ContactPoses:
    """
    Contact frames as estimated: pose i is contact i's frame in frame ``frame``.

    Attributes:
        frame: model frame the poses are expressed in ('' = the base frame).
        positions: contact points, shape (p, 3) [m].
        rotations: contact frame axes (columns x, y, z = inward normal), shape (p, 3, 3).
        links: the link of each pose, as named in the message (None: the scenario's
            contacts, by index).
    """

    frame: str
    positions: np.ndarray
    rotations: np.ndarray
    links: tuple[str, ...] | None = None


@dataclass(frozen=True)
class ContactsReading:
    """
    A contacts message as plain data.

    Attributes:
        frame: ``header.frame_id``: a model frame ('' = the base frame), or
            ``FRAME;LINK_1,...``.
        positions: contact points, shape (p, 3) [m].
        quaternions: contact frame orientations (x, y, z, w), shape (p, 4).
    """

    frame: str
    positions: Any
    quaternions: Any


class Contacts:
    """The contacts input (:class:`~grasp_torque_opt.control.inputs.base.NodeInput`)."""

    name = 'contacts'
    message = 'geometry_msgs/msg/PoseArray'
    qos = 'sensor_data'
    counted = True
    enabled = None
    timeout = 'contacts_timeout'
    grasp_only = True

    def size(self, store, n: int, frame_id: str = '') -> None:
        """Refuse a count of poses that the frame_id does not name, unread."""
        split_frame_id(frame_id, n, len(store.setup.contacts))

    def check(self, store, reading: ContactsReading) -> ContactPoses:
        """
        Check the poses whole and place them as contact frames.

        Raises:
            InputError: wrong count or shape, unknown frame, a bad frame_id or named link
                (:func:`.named_contacts.named_frame`), non-finite values, a non-unit
                quaternion, an implausible contact at the latest joint state.
        """
        positions = np.asarray(reading.positions, dtype=float)
        quaternions = np.asarray(reading.quaternions, dtype=float)
        frame, links = named_frame(store.setup, reading.frame, len(positions))
        rotations = contact_rotations(store.setup.hand.model, len(positions), frame,
                                      positions, quaternions)
        q = latest_q(store)
        check_contacts(store.setup, store.object, q, frame, positions, rotations,
                       store.config, links, store.surfaces, pose_in_use(store, q))
        return ContactPoses(frame, positions, rotations, links)

    def keep(self, store, value: ContactPoses, now: float) -> dict[str, Any]:
        """Keep the contact frames."""
        return {'contacts': value, 'contacts_time': now}

    def stamp_timeout(self, config) -> float:
        """Return contacts_timeout."""
        return config.contacts_timeout

    def stale(self, inputs, config, now: float) -> str:
        """Say that the contacts are older than contacts_timeout (when it is set)."""
        return aged('contacts', inputs.contacts_time, config.contacts_timeout, now)


CONTACTS = Contacts()
