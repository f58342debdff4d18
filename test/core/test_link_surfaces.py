# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""A point's distance to its link's collision shapes: closed forms against coal, on the Allegro."""

from conftest import ALLEGRO, PLANAR
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import resolve_urdf
from grasp_torque_opt.core.link_surfaces import LinkSurfaces
from grasp_torque_opt.core.scenario import load_scenario
import numpy as np
import pinocchio as pin
import pytest

SCENARIO = load_scenario(ALLEGRO)
SETUP = GraspSetup.from_scenario(SCENARIO)
MODEL = SETUP.hand.model


@pytest.fixture(scope='module')
def surfaces():
    return LinkSurfaces.bind(SETUP.hand, resolve_urdf(SCENARIO.urdf, SCENARIO.base_dir))


def placed():
    data = MODEL.createData()
    pin.framesForwardKinematics(MODEL, data, SETUP.q)
    return data


def test_the_scenarios_contacts_lie_on_their_tips(surfaces):
    data = placed()
    links = tuple(c.link for c in SETUP.contacts)
    points = np.array([data.oMf[MODEL.getFrameId(c.link)].act(c.position)
                       for c in SETUP.contacts])
    assert (surfaces.distances(data, links, points) < 1e-4).all()
    # Index and middle named the other way round: each a tip's radius and more away.
    swapped = surfaces.distances(data, (links[1], links[0]) + links[2:], points)
    assert (swapped[:2] > 0.02).all()


def test_the_closed_forms_are_coals(surfaces):
    data = placed()
    rng = np.random.default_rng(5)
    checked = 0
    for link in ('link_7.0', 'link_3.0_tip', 'link_12.0', 'palm_link'):
        for s in surfaces._shapes[link]:
            oMs = data.oMi[s.joint] * s.placement
            for _ in range(20):
                p = oMs.translation + 0.03 * rng.standard_normal(3)
                closed = surfaces._signed(s, oMs, p)
                kind, s.kind = s.kind, 'coal'
                try:
                    by_coal = surfaces._signed(s, oMs, p)
                finally:
                    s.kind = kind
                if closed > 0:  # coal's EPA inside a shape is its penetration depth
                    assert closed == pytest.approx(by_coal, abs=1e-7)
                else:
                    assert by_coal <= 1e-7
                checked += 1
    assert checked == 80


def test_links_without_collision_geometry_are_named(surfaces, planar):
    assert surfaces.bare(SETUP.hand) == []
    doc = load_scenario(PLANAR)  # its URDF has no <collision> element
    planar_surfaces = LinkSurfaces.bind(planar.hand, resolve_urdf(doc.urdf, doc.base_dir))
    assert planar_surfaces.links == ()
    assert set(planar_surfaces.bare(planar.hand)) >= {c.link for c in planar.contacts}
    d = planar_surfaces.distances(planar.hand.data, tuple(c.link for c in planar.contacts),
                                  np.zeros((len(planar.contacts), 3)))
    assert np.isnan(d).all()
