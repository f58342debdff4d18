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
perception sign bug) gave commands that pull, and swapped fingertips put contacts 71 to
95 mm from their own links (docs/node.md, "Input checks"). The rules, in the base frame
at the configuration of the moment:

- a contact point at most ``max_contact_link_distance`` from its own link's frame;
- its normal points into the object (:func:`grasp_torque_opt.core.inward.check_inward_normals`:
  towards the object origin, and into the scenario object's surface where it has one);
- a contact's link is not the root, a frame fixed to the root, nor a joint frame
  (:func:`grasp_torque_opt.core.contact_links.check_contact_links`, when the scenario
  is bound).
"""

from __future__ import annotations

from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.inward import check_inward_normals
from grasp_torque_opt.core.scenario import ObjectSpec
import numpy as np
import pinocchio as pin


def check_contacts(setup: GraspSetup, obj: ObjectSpec | None, q: np.ndarray, frame: str,
                   positions: np.ndarray, rotations: np.ndarray, limit: float,
                   links: tuple[str, ...] | None = None) -> None:
    """
    Check contact poses at configuration ``q``: on their own links, pushing into the object.

    Args:
        setup: the grasp (its hand's model and data, its contacts' links, object origin).
        obj: the scenario's object, or None.
        q: the configuration the links are placed at.
        frame: model frame of the poses ('' = the base frame).
        positions: contact points, shape (p, 3) [m].
        rotations: contact frame axes, shape (p, 3, 3).
        limit: ``max_contact_link_distance`` [m].
        links: each pose's link (None: the scenario's contacts', by index).

    Raises:
        InputError: naming the contact (:func:`check_on_links`, :func:`check_inward`).
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
    check_on_links(points, origins, links, limit)
    check_inward(points, normals, links, setup.object_origin, obj)


def check_on_links(points: np.ndarray, link_origins: np.ndarray, links: tuple[str, ...],
                   limit: float) -> None:
    """
    Refuse a contact point farther than ``limit`` from its own link's frame.

    Args:
        points: contact points, base frame, shape (p, 3) [m].
        link_origins: their links' frame origins, base frame, shape (p, 3) [m].
        links: the links' names, for the message.
        limit: ``max_contact_link_distance`` [m].

    Raises:
        InputError: ``contacts.poses[i].position``.
    """
    d = np.linalg.norm(points - link_origins, axis=1)
    if (d <= limit).all():  # False for NaN as well
        return
    i = int(np.argmax(np.where(np.isnan(d), np.inf, d)))
    raise InputError(f'contacts.poses[{i}].position', f'is {d[i]:.4g} m from its link '
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
