# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Scenarios with contacts given by link only or ``auto``: bound, solved as the hand-made ones."""

import copy
import warnings

from conftest import ALLEGRO, scenario_doc, setup_from_doc
from grasp_torque_opt.core.exceptions import GeometryError, GeometryWarning, InputError
from grasp_torque_opt.core.grasp_maps import compute_grasp_maps
from grasp_torque_opt.core.scenario_fields import ContactSpec
from grasp_torque_opt.methods.dispatch import solve
import numpy as np
import pytest

#: The bundled scenarios whose hand-made contacts are the collision model's: the Allegro's
#: tip spheres (the G1's and Ability's were found by MuJoCo on their meshes' convex
#: hulls, up to 6 mm from the meshes' own nearest points).
BUNDLED = [ALLEGRO]


def links_only(doc):
    doc = copy.deepcopy(doc)
    for contact in doc['grasp']['contacts']:
        contact.pop('position', None)
    return doc


@pytest.mark.parametrize('path', BUNDLED, ids=lambda p: p.stem)
def test_a_links_only_scenario_solves_to_the_bundled_torques(path):
    doc = scenario_doc(path)
    made = setup_from_doc(doc)
    found = setup_from_doc(links_only(doc))
    for a, b in zip(made.contacts, found.contacts):
        assert a.link == b.link
        assert np.linalg.norm(a.position - b.position) < 1e-4  # the files' 0.01 mm rounding
    a, b = solve(made), solve(found)
    assert a.optimal and b.optimal
    # The same grasp up to the written points' rounding: torques within 0.1% of the limit.
    np.testing.assert_allclose(b.tau, a.tau, atol=1e-3 * made.hand.torque_limits.min())
    # Written in full with the found points and normals, the same torques exactly.
    full = copy.deepcopy(doc)
    full['grasp']['contacts'] = [{'link': c.link, 'position': c.position.tolist(),
                                  'normal': c.normal.tolist()} for c in found.contacts]
    np.testing.assert_allclose(solve(setup_from_doc(full)).tau, b.tau, atol=1e-9)


def test_auto_is_the_four_tips_and_solves_alike():
    doc = scenario_doc(ALLEGRO)
    auto = copy.deepcopy(doc)
    auto['grasp']['contacts'] = 'auto'
    setup = setup_from_doc(auto)
    assert [c.link for c in setup.contacts] == [c['link'] for c in doc['grasp']['contacts']]
    np.testing.assert_allclose(solve(setup).tau, solve(setup_from_doc(links_only(doc))).tau,
                               atol=1e-12)


def test_a_link_given_alone_that_does_not_touch_is_named():
    doc = links_only(scenario_doc(ALLEGRO))
    doc['grasp']['joint_positions']['joint_1.0'] -= 0.2
    with pytest.raises(GeometryError, match=r"^grasp\.contacts\[0\]\.link: 'link_3.0_tip' does "
                       r'not touch the object: \d+(\.\d+)? mm from it, more than '
                       r'grasp\.contact_tolerance \(1 mm\)'):
        setup_from_doc(doc)
    doc['grasp']['contact_tolerance'] = 0.05  # a looser tolerance takes it
    assert setup_from_doc(doc).contacts[0].link == 'link_3.0_tip'


def test_auto_without_touch_or_object_is_an_error():
    doc = scenario_doc(ALLEGRO)
    doc['grasp']['contacts'] = 'auto'
    doc['grasp']['object_origin'] = doc['object']['position'] = [0.3, 0.0, 0.0]
    with pytest.raises(GeometryError, match=r'grasp\.contacts: auto: no link within '
                       r'grasp\.contact_tolerance \(1 mm\) of the object \(nearest: '):
        setup_from_doc(doc)
    del doc['object']
    doc['load'] = {'external_wrench': [0, 0, 0, 0, 0, 0]}
    with pytest.raises(InputError, match="grasp.contacts: 'auto' needs the object section"):
        setup_from_doc(doc)


def test_a_normal_without_a_position_keeps_the_links_origin():
    """As before: only a contact given by its link alone is found from geometry."""
    doc = links_only(scenario_doc(ALLEGRO))
    doc['grasp']['contacts'][1]['normal'] = [0.0, 0.0, -1.0]
    with pytest.warns(GeometryWarning, match=r'grasp\.contacts\[1\]\.position: '):
        setup = setup_from_doc(doc)
    np.testing.assert_array_equal(setup.contacts[1].position, np.zeros(3))
    assert setup.contacts[0].position is not None and setup.contacts[0].position.any()


def test_a_written_point_off_the_object_is_warned_about():
    doc = scenario_doc(ALLEGRO)
    with warnings.catch_warnings():
        warnings.simplefilter('error', GeometryWarning)
        setup_from_doc(doc)  # the bundled points are on the ball
    doc['grasp']['contacts'][2]['position'] = [0.0072, 0.0052, 0.0121]  # 4 mm along the tip
    with pytest.warns(GeometryWarning, match=r'grasp\.contacts\[2\]\.position: \d\.\d+ mm '
                      r"(outside|inside) the object's sphere surface, more than "
                      r'grasp\.contact_tolerance \(1 mm\)'):
        setup_from_doc(doc)


def test_an_unbound_links_only_contact_is_named_not_a_traceback():
    setup = setup_from_doc(scenario_doc(ALLEGRO))
    contacts = [ContactSpec(link='link_3.0_tip', position=None)] + setup.contacts[1:]
    with pytest.raises(InputError, match=r'grasp\.contacts\[0\]\.position: not found yet'):
        compute_grasp_maps(setup.hand, setup.q, contacts, setup.object_origin)
