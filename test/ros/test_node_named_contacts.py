# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Contact estimates with each contact's link named (issue 25, item 2).

On the Allegro ball grasp: ``contacts`` with ``header.frame_id`` ``FRAME;LINK_1,...``.
Each command is compared with the core's solve of a grasp written with those contacts
(the scenario's points, the default normals and tangents): an independent computation.
"""

import dataclasses

from conftest import ALLEGRO
from cycle_inputs import base_poses, joint_state
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.methods.dispatch import solve
import numpy as np
import pytest
from ros_harness import Harness

SETUP = GraspSetup.from_file(ALLEGRO)
LINKS = [c.link for c in SETUP.contacts]
MODEL = SETUP.hand.model
LIFTED = 1  # the middle finger is lifted (three contacts left)
#: A fingertip's proximal flexion joint.
PROXIMAL = {'link_3.0_tip': 'joint_1.0', 'link_7.0_tip': 'joint_5.0',
            'link_11.0_tip': 'joint_9.0', 'link_15.0_tip': 'joint_13.0'}


def lifted_q():
    """Give the grasp's joint positions with the lifted finger's proximal joint opened."""
    q = SETUP.q.copy()
    q[MODEL.joints[MODEL.getJointId(PROXIMAL[LINKS[LIFTED]])].idx_q] -= 0.1
    return q


def named(links, frame=''):
    return f"{frame};{','.join(links)}"


def rejections(h):
    return h.node.controller.counters.rejected['contacts']


def diag(h, key, value):
    """Wait for a diagnostics message whose ``key`` is ``value``; give the last one."""
    h.spin_until(lambda: bool(h.diagnostics) and h.diagnostics[-1].get(key) == value, 3.0)
    return h.diagnostics[-1]


def test_the_four_contacts_named_give_the_unnamed_forms_command():
    h = Harness(ALLEGRO)
    try:
        names, pos = joint_state(SETUP)
        points, quat = base_poses(SETUP)
        h.send_contacts('', points, quat)
        h.spin_until(lambda: h.node.controller.inputs.contacts is not None, 2.0)
        h.send_joint_state(names, pos)
        unnamed = h.next_command()
        np.testing.assert_allclose(unnamed, solve(SETUP).tau, atol=1e-6)
        h.send_contacts(named(LINKS, SETUP.hand.base_frame), points, quat)
        assert h.spin_until(lambda: h.node.controller.inputs.contacts.links == tuple(LINKS),
                            2.0)
        h.send_joint_state(names, pos)
        np.testing.assert_allclose(h.next_command(), unnamed, atol=1e-9)
        d = diag(h, 'contacts.links', ','.join(LINKS))
        assert d['contacts.source'] == 'contacts topic' and d['contacts.changes'] == '0'
        assert rejections(h) == 0
    finally:
        h.close()


def test_three_named_contacts_give_the_three_contact_grasps_command():
    q = lifted_q()
    three = [c for i, c in enumerate(SETUP.contacts) if i != LIFTED]
    ref = solve(dataclasses.replace(SETUP, q=q, contacts=three))
    assert ref.optimal
    four = solve(dataclasses.replace(SETUP, q=q))
    assert np.abs(four.tau - ref.tau).max() > 1e-3  # the lifted contact mattered
    links = tuple(c.link for c in three)
    # The rate rule steps across a set change too (test/control/test_rates.py); here
    # the three contacts' command is reached in one cycle.
    h = Harness(ALLEGRO)
    try:
        names, pos = joint_state(SETUP, q)
        points, quat = base_poses(SETUP, q)
        h.send_contacts(named(LINKS), points, quat)
        h.spin_until(lambda: h.node.controller.inputs.contacts is not None, 2.0)
        h.send_joint_state(names, pos)
        np.testing.assert_allclose(h.next_command(), four.tau, atol=1e-6)
        keep = [i for i in range(len(LINKS)) if i != LIFTED]
        h.send_contacts(named(links), points[keep], quat[keep])
        assert h.spin_until(lambda: h.node.controller.inputs.contacts.links == links, 2.0)
        h.send_joint_state(names, pos)
        cmd = h.next_command()
        np.testing.assert_allclose(cmd, ref.tau, atol=1e-6)
        assert h.node.controller.last.solution.optimal
        assert len(h.node.controller.last.maps.links) == 3
        d = diag(h, 'contacts.links', ','.join(links))
        assert d['contacts.changes'] == '1'
        # The finger comes back: four again, a second change.
        h.send_contacts(named(LINKS), points, quat)
        assert h.spin_until(lambda: len(h.node.controller.inputs.contacts.links) == 4, 2.0)
        h.send_joint_state(names, pos)
        np.testing.assert_allclose(h.next_command(), four.tau, atol=1e-6)
        assert diag(h, 'contacts.changes', '2')['contacts.links'] == ','.join(LINKS)
    finally:
        h.close()


BAD = [
    # The index tip's pose named on the thumb tip and back: 82 mm from the named link.
    ('wrong link', lambda p: named([LINKS[3]] + LINKS[1:3] + [LINKS[0]]),
     "from the surface of its link 'link_15.0_tip' (its collision geometry), beyond "
     'max_contact_surface_distance (5 mm): a contact of another finger'),
    ('unknown link', lambda p: named(LINKS[:3] + ['link_99_tip']),
     "contacts.header.frame_id link 4: unknown frame 'link_99_tip'"),
    ('root', lambda p: named(LINKS[:3] + [MODEL.frames[1].name]),
     f"'{MODEL.frames[1].name}' is the root"),
    ('duplicate', lambda p: named(LINKS[:3] + [LINKS[0]]),
     f"'{LINKS[0]}' is named twice (links 1 and 4)"),
    ('two separators', lambda p: ';' + named(LINKS), "has more than one ';'"),
    ('no link', lambda p: 'base;', "names no link after ';'"),
    ('empty name', lambda p: named(LINKS[:2] + ['', LINKS[3]]), 'link 3 is empty'),
    ('count', lambda p: named(LINKS[:3]), '4 poses for 3 named links'),
]


@pytest.mark.parametrize('case', BAD, ids=[b[0] for b in BAD])
def test_a_bad_named_message_is_rejected_and_never_used(case):
    _, frame_id, why = case
    h = Harness(ALLEGRO)
    try:
        names, pos = joint_state(SETUP)
        points, quat = base_poses(SETUP)
        h.send_contacts(named(LINKS), points, quat)
        h.spin_until(lambda: h.node.controller.inputs.contacts is not None, 2.0)
        h.send_joint_state(names, pos)
        good = h.next_command()
        kept = h.node.controller.inputs.contacts
        h.send_contacts(frame_id(points), points, quat)
        assert h.spin_until(lambda: rejections(h) == 1, 2.0)
        assert why in h.node.controller.last_rejection, h.node.controller.last_rejection
        assert h.node.controller.inputs.contacts is kept
        h.send_joint_state(names, pos)
        np.testing.assert_allclose(h.next_command(), good, atol=1e-9)
        d = diag(h, 'rejected.contacts', '1')
        assert why in d['last_rejection'] and d['contacts.changes'] == '0'
    finally:
        h.close()
