# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Contact estimates with each contact's link named, on the ``contacts`` topic.

A standard ``geometry_msgs/PoseArray`` carries them: its ``header.frame_id`` is
``FRAME;LINK_1,LINK_2,...`` (FRAME as for the plain form, '' = the base frame), then one
pose per named link, in order (docs/node.md, "Inputs"). A plain ``FRAME`` keeps the old
meaning: one pose per scenario contact, matched by index. The rules on the names:

- 1 to :data:`MAX_NAMED_CONTACTS` links (or the scenario's contact count, if larger),
  each named once, as many poses as links;
- each a frame of the hand that a joint moves
  (:func:`grasp_torque_opt.core.contact_links.check_contact_links`: not the root or the
  base link, a frame fixed to it, nor a joint frame).

Each pose is then checked on ITS named link (:mod:`.plausible`), on receipt and again in
each cycle (:func:`topic_contacts`, which also counts the changes of the set).
"""

from __future__ import annotations

from grasp_torque_opt.control.checks import show
from grasp_torque_opt.control.plausible import check_surfaces, Placed, points_inward
from grasp_torque_opt.core.contact_links import check_contact_links
from grasp_torque_opt.core.exceptions import FrameNotFound, InputError
from grasp_torque_opt.core.scenario_fields import ContactSpec
import numpy as np

#: The most links one message may name (unless the scenario has more contacts).
MAX_NAMED_CONTACTS = 10
#: Where the names are, in messages.
FIELD = 'contacts.header.frame_id'


def split_frame_id(frame_id: str, poses: int, scenario_contacts: int
                   ) -> tuple[str, tuple[str, ...] | None]:
    """
    Split a ``contacts`` frame_id into its frame and its named links, and check the count.

    Args:
        frame_id: ``FRAME`` or ``FRAME;LINK_1,...,LINK_n``.
        poses: the message's number of poses.
        scenario_contacts: the scenario's number of contacts.

    Returns:
        The frame ('' = the base frame) and the links (None: the scenario's contacts, by
        index).

    Raises:
        InputError: more than one ';', no link or an empty name after it, more links than
            the bound, a pose count other than the links' (or, plain, the scenario's).
    """
    frame, sep, names = frame_id.partition(';')
    if not sep:
        if poses != scenario_contacts:
            raise InputError('contacts', f'{poses} poses for {scenario_contacts} contacts '
                             "(name each pose's link: frame_id 'FRAME;LINK_1,...')")
        return frame, None
    if ';' in names:
        raise InputError(FIELD, f"'{show(frame_id)}' has more than one ';' (the form is "
                         "'FRAME;LINK_1,LINK_2,...')")
    links = tuple(name.strip() for name in names.split(','))
    if not names.strip():
        raise InputError(FIELD, f"'{show(frame_id)}' names no link after ';' (the form is "
                         "'FRAME;LINK_1,LINK_2,...')")
    if '' in links:
        raise InputError(FIELD, f"'{show(frame_id)}': link {links.index('') + 1} is empty")
    bound = max(MAX_NAMED_CONTACTS, scenario_contacts)
    if len(links) > bound:
        raise InputError(FIELD, f'names {len(links)} links, more than {bound}')
    if poses != len(links):
        raise InputError('contacts', f'{poses} poses for {len(links)} named links')
    return frame.strip(), links


def named_frame(setup, frame_id: str, poses: int) -> tuple[str, tuple[str, ...] | None]:
    """
    Give a ``contacts`` message's frame and named links, every rule on them checked.

    Args:
        setup: the grasp (its hand, its number of contacts).
        frame_id: the message's ``header.frame_id``.
        poses: its number of poses.

    Raises:
        InputError: as :func:`split_frame_id` and :func:`check_named_links`.
    """
    frame, links = split_frame_id(frame_id, poses, len(setup.contacts))
    if links is not None:
        check_named_links(setup.hand, links)
    return frame, links


def check_named_links(hand, links: tuple[str, ...]) -> None:
    """
    Refuse a named link that is unknown, named twice, or not moved by a joint.

    Args:
        hand: the hand (its model and base link).
        links: the named links, in order.

    Raises:
        InputError: naming the link and what is wrong with it.
    """
    model = hand.model
    seen: dict[str, int] = {}
    for i, link in enumerate(links):
        if not model.existFrame(link):
            raise FrameNotFound(f'{FIELD} link {i + 1}', show(link),
                                {f.name for f in model.frames})
        if link in seen:
            raise InputError(f'{FIELD} link {i + 1}', f"'{show(link)}' is named twice (links "
                             f'{seen[link] + 1} and {i + 1}): one pose per link')
        seen[link] = i
    check_contact_links(model, list(links), field=f'{FIELD}.links', base=hand.base_link)


def topic_contacts(cycle, cp, origin: np.ndarray) -> list[ContactSpec]:
    """
    Give the cycle's contacts from the topic's poses, placed at its configuration.

    The hand's data holds the cycle's placements. The set's links (named, else the
    scenario's by index) are counted on ``cycle.topic_links`` / ``topic_changes`` as the
    geometry's set is.

    Args:
        cycle: the :class:`~grasp_torque_opt.control.cycle.Cycle`.
        cp: the :class:`~grasp_torque_opt.control.inputs.contacts.ContactPoses` in force.
        origin: the object origin in use (base frame).

    Raises:
        InputError: a contact point beyond ``max_contact_distance``, off its link's
            surface or the object's (:func:`~.plausible.check_surfaces`), a normal pointing
            away from the object origin (at this configuration).
    """
    setup = cycle.setup
    hand = setup.hand
    model, data = hand.model, hand.data
    base = None if hand.base_link is None else data.oMf[model.getFrameId(hand.base_link)]
    oMF = data.oMf[model.getFrameId(cp.frame or hand.base_frame)]
    if base is not None:  # the grasp is written in the base link's frame
        oMF = base.actInv(oMF)
    contacts, points, normals, origins = [], [], [], []
    limit = cycle.config.max_contact_distance
    links = cp.links or tuple(c.link for c in setup.contacts)
    for i, (link, p, R) in enumerate(zip(links, cp.positions, cp.rotations)):
        p_base = oMF.act(p)
        distance = float(np.linalg.norm(p_base))
        if distance > limit:
            raise InputError(f'contacts.poses[{i}].position',
                             f'is {distance:.6g} m from the base origin, beyond '
                             f'max_contact_distance ({limit} m)')
        R_base = oMF.rotation @ R
        oMl = data.oMf[model.getFrameId(link)]
        if base is not None:
            oMl = base.actInv(oMl)
        contacts.append(ContactSpec(link=link, position=oMl.actInv(p_base),
                                    normal=R_base[:, 2], tangent=R_base[:, 0]))
        points.append(p_base)
        normals.append(R_base[:, 2])
        origins.append(oMl.translation)
    # Checked whole on receipt (at the joint state of then); the cheap, vectorized part
    # runs again here, since the links have moved since.
    points, normals = np.array(points), np.array(normals)
    check_surfaces(Placed(points, links, data, base, np.array(origins)), cycle.surfaces,
                   cycle.config, cycle.object, cycle.pose_in_use)
    i = points_inward(points, normals, origin)
    if i >= 0:
        raise InputError(f'contacts.poses[{i}].orientation', 'the normal of the contact '
                         f"on '{links[i]}' points away from the object origin at this "
                         'configuration: the torques would pull')
    if links != cycle.topic_links:  # a change of the set, counted as the geometry's are
        cycle.topic_changes += cycle.topic_links is not None
        cycle.topic_links = links
    return contacts
