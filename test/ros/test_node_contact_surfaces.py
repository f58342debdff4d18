# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Contacts on the wrong finger are refused by the links' own collision geometry (issue 33, 2).

Before, a contact was checked only within ``max_contact_link_distance`` (50 mm) of its
link's frame: the index and middle tips named the other way round (each pose 33.6 mm
from its link) and a phantom fifth contact on ``link_7.0`` were accepted and commanded.
Each is sent here in the plain, the named and the name-mapped forms, on the real node
and the Allegro URDF's coal shapes; the commands that follow must be the nominal grasp's.
"""

import dataclasses

from conftest import ALLEGRO, PLANAR
from cycle_inputs import base_poses, joint_state, phantom as shared_phantom
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.methods.dispatch import solve
from lifecycle_msgs.msg import Transition
import numpy as np
import pytest
from ros_harness import Harness, LifecycleHarness
from test_name_map import NAME_MAP, renamed, write_renamed_urdf

SETUP = GraspSetup.from_file(ALLEGRO)
LINKS = [c.link for c in SETUP.contacts]
SWAP = [1, 0, 2, 3]  # the index and middle tips' poses exchanged


def named(links, frame=''):
    return f"{frame};{','.join(links)}"


def phantom(links=('link_7.0',)):
    """
    Give the four poses and one more at each of ``links``' frames, its normal to the ball.

    Such a point is on its link's own box (its collision shape), 0 mm from its frame: the
    frame rule and the link's surface both take it; only the object's surface refuses it.
    """
    return shared_phantom(SETUP, links)


def refused_and_not_commanded(h, send, why, rename=str):
    """Send a lie; it must be counted, named, and the commands stay the nominal grasp's."""
    names, pos = joint_state(SETUP)
    names = [rename(n) for n in names]
    h.send_joint_state(names, pos)
    first = h.next_command()
    assert first is not None
    nominal = solve(dataclasses.replace(SETUP)).tau
    np.testing.assert_allclose(first, nominal, atol=1e-6)
    send()
    h.assert_contacts_refused(why, names, pos, nominal, atol=1e-6, timeout=3.0)


def test_the_true_contacts_are_on_their_links_surfaces_and_accepted():
    h = Harness(ALLEGRO)
    try:
        h.send_joint_state(*joint_state(SETUP))
        assert h.next_command() is not None
        points, quat = base_poses(SETUP)
        h.send_contacts('', points, quat)
        h.send_contacts(named(LINKS), points, quat)
        assert h.spin_until(lambda: h.node.controller.inputs.contacts is not None, 3.0)
        assert h.node.controller.counters.rejected['contacts'] == 0
    finally:
        h.close()


@pytest.mark.parametrize('form', ['plain', 'named'])
def test_index_and_middle_swapped_are_refused_and_named(form):
    h = Harness(ALLEGRO)
    try:
        points, quat = base_poses(SETUP)
        frame = '' if form == 'plain' else named(LINKS)
        refused_and_not_commanded(
            h, lambda: h.send_contacts(frame, points[SWAP], quat[SWAP]),
            'contacts.poses[0].position: is 21.6 mm from the surface of its link '
            "'link_3.0_tip' (its collision geometry), beyond max_contact_surface_distance")
    finally:
        h.close()


def test_a_phantom_fifth_contact_on_link_7_is_refused_and_named():
    h = Harness(ALLEGRO)
    try:
        points, quat = phantom()
        refused_and_not_commanded(
            h, lambda: h.send_contacts(named(LINKS + ['link_7.0']), points, quat),
            "contacts.poses[4].position: (on 'link_7.0') is ")
        assert "off the object's surface at the pose in use, beyond uncertainty.pose + " \
            'max_contact_surface_distance (6 mm)' in h.node.controller.last_rejection
    finally:
        h.close()


def test_the_swap_through_name_map_is_refused_and_named(tmp_path):
    urdf = write_renamed_urdf(tmp_path)
    h = Harness(ALLEGRO, robot_description=str(urdf), name_map=NAME_MAP)
    try:
        points, quat = base_poses(SETUP)
        links = [renamed(link) for link in LINKS]
        refused_and_not_commanded(
            h, lambda: h.send_contacts(named(links), points[SWAP], quat[SWAP]),
            "from the surface of its link 'ah_link03_tip'", rename=renamed)
    finally:
        h.close()


def test_links_without_collision_geometry_keep_the_frame_rule_with_one_warning():
    """The planar hand's URDF has no <collision>: its contacts keep max_contact_link_distance."""
    h = LifecycleHarness(PLANAR)
    try:
        assert h.transition(Transition.TRANSITION_CONFIGURE)
        assert h.spin_until(lambda: any('no collision geometry' in m.msg for m in h.logs), 3.0)
        warned = [m.msg for m in h.logs if 'no collision geometry' in m.msg]
        assert len(warned) == 1 and warned[0].startswith('contacts: 6 link(s) a joint moves ')
        assert 'finger1_tip' in warned[0] and 'checked by max_contact_link_distance' in warned[0]
        assert h.node.controller.store.surfaces.bare(h.node.controller.setup.hand)
    finally:
        h.close()


def test_a_ten_link_set_is_refused_at_its_first_link_off_the_object():
    h = Harness(ALLEGRO)
    try:
        extra = ['link_7.0', 'link_3.0', 'link_11.0', 'link_15.0', 'link_6.0', 'link_2.0']
        points, quat = phantom(extra)
        refused_and_not_commanded(
            h, lambda: h.send_contacts(named(LINKS + extra), points, quat),
            "contacts.poses[4].position: (on 'link_7.0') is ")
    finally:
        h.close()
