# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
A contact's link must be a body that a joint moves.

A contact named on the root (or a frame welded to it) or on a joint frame was bound and
certified, e.g. through a name map sending a fingertip to ``palm_link`` (issue 27).
"""

from __future__ import annotations

from grasp_torque_opt.core.exceptions import InputError
import pinocchio as pin


def check_contact_links(model: pin.Model, links: list[str], field: str = 'grasp.contacts',
                        base: str | None = None) -> None:
    """
    Refuse a contact link that cannot carry a fingertip's contact.

    A contact on the root (or a frame welded to it) gives the fingers nothing to push
    with; a joint frame is no body. Either way the grasp map would be certified for a
    contact no finger makes.

    Args:
        model: the hand's model.
        links: the contacts' links (the URDF's names, after the name map).
        field: the field named in the message.
        base: the hand's base frame (``hand.base_link`` in a robot: a link fixed to it
            is the palm, not a finger), or None for the root.

    Raises:
        InputError: ``<field>[i].link``, naming the link and why.
    """
    root, word = (model.frames[1].name if len(model.frames) > 1 else ''), 'root'
    if base is not None and model.existFrame(base):
        root, word = base, 'base link'
    fixed = model.frames[model.getFrameId(root)].parentJoint if root else 0
    for i, link in enumerate(links):
        if not model.existFrame(link):
            continue  # the binding names unknown frames itself
        frame = model.frames[model.getFrameId(link)]
        if frame.type in (pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT):
            why = 'is a joint frame, not a link'
        elif frame.parentJoint == fixed:
            why = f"is the {word} '{root}'" if link == root else \
                f"is fixed to the {word} '{root}'"
        else:
            continue
        raise InputError(f'{field}[{i}].link', f"'{link}' {why}: a contact must be on a "
                         'link that a joint moves (check the name map)')
