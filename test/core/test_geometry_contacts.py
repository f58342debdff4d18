# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Contacts from geometry on the real Allegro URDF: the grasp, rolling, lift-off, bad input."""

from conftest import ALLEGRO
from grasp_torque_opt.core.exceptions import FrameNotFound, GeometryError
from grasp_torque_opt.core.geometry_contacts import GeometryContacts
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import Hand, resolve_urdf
from grasp_torque_opt.core.object_geometry import object_pose, ObjectShape
from grasp_torque_opt.core.scenario import load_scenario, ObjectSpec
import numpy as np
import pinocchio as pin
import pytest

TIPS = ['link_3.0_tip', 'link_7.0_tip', 'link_11.0_tip', 'link_15.0_tip']
TIP_RADIUS = 0.012  # the URDF's fingertip spheres [m]


@pytest.fixture(scope='module')
def grasp():
    scenario = load_scenario(ALLEGRO)
    setup = GraspSetup.from_scenario(scenario)
    return scenario, setup, resolve_urdf(scenario.urdf, scenario.base_dir)


def ball_pose(scenario, centre=None):
    return object_pose(scenario.object.position if centre is None else centre)


def tip_centre(setup, q, link):
    data = setup.hand.model.createData()
    pin.framesForwardKinematics(setup.hand.model, data, q)
    return data.oMf[setup.hand.model.getFrameId(link)]


def test_the_computed_contacts_are_the_hand_made_ones(grasp):
    scenario, setup, urdf = grasp
    model = GeometryContacts.bind(setup.hand, urdf, scenario.object, links=TIPS)
    assert all(model.closed_form.values())
    found = model.contacts(setup.q, ball_pose(scenario))
    assert found.links == tuple(TIPS)
    written = np.array([c.position for c in scenario.contacts])
    assert np.max(np.linalg.norm(found.points_link - written, axis=1)) < 1e-4
    normals = setup.maps().rotations[:, :, 2]  # the scenario's: towards the ball's centre
    angles = np.arccos(np.clip(np.sum(found.normals * normals, axis=1), -1.0, 1.0))
    assert np.max(angles) < 0.01
    # Inward: from the point towards the ball's centre, the object's inward normal.
    towards = scenario.object.position - found.object_points
    np.testing.assert_allclose(found.normals, towards / np.linalg.norm(towards, axis=1)[:, None],
                               atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(found.object_points - scenario.object.position,
                                              axis=1), 0.04, atol=1e-12)
    assert np.all(np.abs(found.distances) < 1e-4)


def test_auto_finds_the_four_tips_and_no_other_link(grasp):
    scenario, setup, urdf = grasp
    model = GeometryContacts.bind(setup.hand, urdf, scenario.object)
    assert 'palm_link' not in model.links  # fixed to the root: it cannot push
    assert set(model.links) > set(TIPS)
    assert model.contacts(setup.q, ball_pose(scenario)).links == tuple(TIPS)
    # The next nearest links are the IK's 2 mm clearance away: outside 1 mm, inside 3 mm.
    assert len(model.contacts(setup.q, ball_pose(scenario), tolerance=3e-3).links) > 4


@pytest.mark.parametrize('shape,size,centre', [
    ('sphere', [0.04], None),
    ('box', [0.05, 0.04, 0.05], None),
    ('cylinder', [0.03, 0.05], None),
    ('box', [0.03, 0.06, 0.045], [0.062, 0.004, 0.03]),
])
def test_coal_and_the_closed_form_agree(grasp, shape, size, centre):
    """The closed form against coal's GJK/EPA on the same inputs, turned and moved."""
    scenario, setup, urdf = grasp
    rng = np.random.default_rng(len(size) + (centre is not None))
    spec = ObjectSpec(shape, np.array(size), 0.1, scenario.object.position, np.zeros(3))
    closed = GeometryContacts.bind(setup.hand, urdf, spec, links=TIPS, max_penetration=0.05)
    general = GeometryContacts.bind(setup.hand, urdf, spec, links=TIPS, max_penetration=0.05,
                                    analytic=False)
    assert all(closed.closed_form.values()) and not any(general.closed_form.values())
    for _ in range(5):
        q = setup.q.copy()
        q[setup.hand.idx_q] += rng.normal(scale=0.05, size=setup.hand.m)
        pose = object_pose(np.array(centre or scenario.object.position)
                           + rng.normal(scale=0.002, size=3), rng.normal(scale=0.3, size=3))
        a = closed.contacts(q, pose, tolerance=1.0)
        b = general.contacts(q, pose, tolerance=1.0)
        assert a.links == b.links == tuple(TIPS)
        np.testing.assert_allclose(a.distances, b.distances, atol=1e-7)
        np.testing.assert_allclose(a.points, b.points, atol=1e-6)
        np.testing.assert_allclose(a.points_link, b.points_link, atol=1e-6)
        np.testing.assert_allclose(a.object_points, b.object_points, atol=1e-6)
        np.testing.assert_allclose(a.normals, b.normals, atol=1e-5)


def test_the_contact_rolls_over_the_tip_as_the_finger_moves(grasp):
    """The ball follows the index tip; the contact is on the line of centres, in the tip."""
    scenario, setup, urdf = grasp
    model = GeometryContacts.bind(setup.hand, urdf, scenario.object, links=['link_3.0_tip'])
    j = setup.hand.model.joints[setup.hand.model.getJointId('joint_3.0')].idx_q
    offset = scenario.object.position - tip_centre(setup, setup.q, 'link_3.0_tip').translation
    first = None
    for step in np.linspace(-0.3, 0.3, 13):
        q = setup.q.copy()
        q[j] += step
        oMf = tip_centre(setup, q, 'link_3.0_tip')
        centre = oMf.translation + offset  # the ball moved with the tip: still tangent
        found = model.contacts(q, ball_pose(scenario, centre))
        assert found.links == ('link_3.0_tip',)
        n = offset / np.linalg.norm(offset)
        expected = oMf.translation + TIP_RADIUS * n  # on the line of centres
        np.testing.assert_allclose(found.points[0], expected, atol=1e-12)
        np.testing.assert_allclose(found.points_link[0], oMf.actInv(expected), atol=1e-12)
        np.testing.assert_allclose(found.normals[0], n, atol=1e-12)
        first = found.points_link[0] if first is None else first
    # The point moved over the tip (0.6 rad of a 12 mm sphere: about 7 mm), not fixed in it.
    assert np.linalg.norm(found.points_link[0] - first) > 5e-3


def test_a_finger_lifted_off_has_no_contact_and_back_has_it_again(grasp):
    scenario, setup, urdf = grasp
    model = GeometryContacts.bind(setup.hand, urdf, scenario.object)
    j = setup.hand.model.joints[setup.hand.model.getJointId('joint_1.0')].idx_q
    q = setup.q.copy()
    q[j] -= 0.2  # the index opens
    lifted = model.contacts(q, ball_pose(scenario))
    assert lifted.links == ('link_7.0_tip', 'link_11.0_tip', 'link_15.0_tip')
    assert model.distances(q, ball_pose(scenario))['link_3.0_tip'] > 5e-3
    q[j] += 0.2
    assert model.contacts(q, ball_pose(scenario)).links == tuple(TIPS)


def test_a_link_without_collision_geometry_is_named(grasp):
    scenario, setup, urdf = grasp
    xml = urdf.read_text()
    start = xml.index('<link name="link_3.0_tip">')
    a, b = xml.index('<collision>', start), xml.index('</collision>', start)
    xml = xml[:a] + xml[b + len('</collision>'):]
    hand = Hand.from_urdf_string(xml, scenario.joints, 0.7)
    with pytest.raises(GeometryError, match=r"grasp\.contacts\[0\]\.link: link 'link_3.0_tip' "
                       'has no collision geometry'):
        GeometryContacts.bind(hand, xml, scenario.object, links=['link_3.0_tip'])
    with pytest.raises(FrameNotFound, match=r"grasp\.contacts\[0\]\.link: unknown frame 'tip'"):
        GeometryContacts.bind(hand, xml, scenario.object, links=['tip'])


def _obj(path, vertices, faces):
    with open(path, 'w') as f:
        for v in vertices:
            f.write('v {} {} {}\n'.format(*v))
        for t in faces:
            f.write('f {} {} {}\n'.format(*(i + 1 for i in t)))
    return path


BOX_FACES = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7),
             (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]


def box_mesh(path, edges):
    h = 0.5 * np.asarray(edges)
    vertices = [(sx * h[0], sy * h[1], sz * h[2]) for sx in (-1, 1) for sy in (-1, 1)
                for sz in (-1, 1)]
    return _obj(path, vertices, BOX_FACES)


def test_a_mesh_box_gives_the_boxs_contacts(grasp, tmp_path):
    """A box as a triangle mesh (coal's BVH) against the box's closed form."""
    scenario, setup, urdf = grasp
    edges = [0.03, 0.06, 0.045]
    mesh = ObjectShape.mesh_file(box_mesh(tmp_path / 'box.obj', edges))
    spec = ObjectSpec('box', np.array(edges), 0.1, np.zeros(3), np.zeros(3))
    a = GeometryContacts.bind(setup.hand, urdf, mesh, links=TIPS)
    b = GeometryContacts.bind(setup.hand, urdf, spec, links=TIPS)
    pose = object_pose([0.062, 0.004, 0.03], [0.1, -0.2, 0.05])
    x, y = a.contacts(setup.q, pose, tolerance=1.0), b.contacts(setup.q, pose, tolerance=1.0)
    assert x.links == y.links == tuple(TIPS)
    np.testing.assert_allclose(x.distances, y.distances, atol=1e-7)
    np.testing.assert_allclose(x.points, y.points, atol=1e-6)
    np.testing.assert_allclose(x.normals, y.normals, atol=1e-5)


def test_a_degenerate_or_unreadable_mesh_is_refused(grasp, tmp_path):
    scenario, setup, urdf = grasp
    flat = _obj(tmp_path / 'flat.obj', [(0, 0, 0), (0.05, 0, 0), (0, 0.05, 0), (0.05, 0.05, 0)],
                [(0, 1, 2), (1, 3, 2)])
    with pytest.raises(GeometryError, match=r'object\.mesh: the mesh .*flat\.obj is degenerate'):
        GeometryContacts.bind(setup.hand, urdf, ObjectShape.mesh_file(flat), links=TIPS)
    (tmp_path / 'junk.obj').write_text('not a mesh\n')
    with pytest.raises(GeometryError, match=r'object\.mesh: cannot read the mesh'):
        GeometryContacts.bind(setup.hand, urdf, ObjectShape.mesh_file(tmp_path / 'junk.obj'),
                              links=TIPS)
    with pytest.raises(GeometryError, match='mesh file not found'):
        GeometryContacts.bind(setup.hand, urdf, ObjectShape.mesh_file(tmp_path / 'none.obj'))


def test_an_object_inside_a_link_or_too_deep_is_an_error(grasp):
    scenario, setup, urdf = grasp
    centre = tip_centre(setup, setup.q, 'link_3.0_tip').translation
    small = ObjectSpec('sphere', np.array([0.004]), 0.01, centre, np.zeros(3))
    model = GeometryContacts.bind(setup.hand, urdf, small, links=TIPS)
    with pytest.raises(GeometryError, match="object's centre is inside link 'link_3.0_tip'"):
        model.contacts(setup.q, object_pose(centre + 0.002))
    model = GeometryContacts.bind(setup.hand, urdf, scenario.object, links=TIPS)
    towards = centre - scenario.object.position
    deeper = scenario.object.position + 0.008 * towards / np.linalg.norm(towards)
    with pytest.raises(GeometryError, match=r"link 'link_3.0_tip' is 8\.0\d* mm inside the "
                       'object, more than 5 mm'):
        model.contacts(setup.q, ball_pose(scenario, deeper))
