# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The MuJoCo model of a scenario: what it keeps of the URDF, and what it refuses."""

import copy

from conftest import ALLEGRO, CONFIG, PLANAR, scenario_doc
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.scenario import load_scenario, parse_scenario
from grasp_torque_opt.sim.model import build_model, SimSettings
import mujoco
import numpy as np
import pinocchio as pin
import pytest


@pytest.fixture(scope='module')
def allegro_sim():
    return build_model(load_scenario(ALLEGRO))


def test_gravity_torques_equal_pinocchios(allegro_sim, allegro):
    """Balanceinertia changes no mass or centre of mass: MuJoCo's g(q) is Pinocchio's."""
    m = allegro_sim.model
    d = mujoco.MjData(m)
    model = allegro.hand.model.copy()
    model.gravity.linear = np.array([9.81, 0.0, 0.0])
    data = model.createData()
    pin.seed(7)
    for _ in range(5):
        q = pin.randomConfiguration(model)
        d.qpos[allegro_sim.qpos_adr] = q[allegro.hand.idx_q]
        d.qvel[:] = 0.0
        mujoco.mj_forward(m, d)
        g = pin.computeGeneralizedGravity(model, data, q)[allegro.hand.idx_v]
        assert np.linalg.norm(g) > 1e-3
        np.testing.assert_allclose(d.qfrc_bias[allegro_sim.dof_adr], g, atol=1e-9)


def test_what_the_model_keeps_and_drops(allegro_sim):
    m = allegro_sim.model
    names = [m.body(b).name for b in range(m.nbody)]
    assert {'link_3.0_tip', 'link_7.0_tip', 'link_11.0_tip', 'link_15.0_tip'} <= set(names)
    assert np.all(m.dof_frictionloss[allegro_sim.dof_adr] == 0.0)  # the URDF says 5-12 N m
    assert np.all(m.dof_damping[allegro_sim.dof_adr] == 0.0)
    hand = [g for g in range(m.ngeom) if m.geom_bodyid[g] != allegro_sim.object_body]
    # Hand geoms touch the object only, never each other.
    assert all((m.geom_contype[a] & m.geom_conaffinity[b]) == 0 for a in hand for b in hand)
    obj = [g for g in range(m.ngeom) if m.geom_bodyid[g] == allegro_sim.object_body]
    assert all(m.geom_contype[obj[0]] & m.geom_conaffinity[g] for g in hand)
    np.testing.assert_allclose(m.geom_friction[obj[0]], [0.5, 0.005, 0.0])
    assert m.geom_condim[obj[0]] == 4 and m.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
    # A uniform ball of 0.15 kg, radius 0.04 m: inertia 2/5 m r^2 at its centre.
    b = allegro_sim.object_body
    assert m.body_mass[b] == pytest.approx(0.15)
    np.testing.assert_allclose(m.body_inertia[b], 0.4 * 0.15 * 0.04 ** 2, rtol=1e-9)
    np.testing.assert_allclose(m.body_ipos[b], 0.0, atol=1e-12)
    np.testing.assert_allclose(m.opt.gravity, [9.81, 0.0, 0.0])


def test_settings_override_friction_mass_and_damping():
    sim = build_model(load_scenario(ALLEGRO), SimSettings(mu_tangential=0.3, mu_torsional=0.002,
                                                          mass=0.5, joint_damping=0.02))
    m = sim.model
    assert sim.mu_tangential == 0.3 and m.body_mass[sim.object_body] == pytest.approx(0.5)
    assert np.all(m.geom_friction[:, :2] == [0.3, 0.002])
    assert np.all(m.dof_damping[sim.dof_adr] == 0.02)


@pytest.mark.parametrize('shape,size,inertia_z', [
    ('box', [0.06, 0.04, 0.02], 0.2 * (0.06 ** 2 + 0.04 ** 2) / 12),
    ('cylinder', [0.03, 0.08], 0.2 * 0.03 ** 2 / 2),
])
def test_box_and_cylinder(shape, size, inertia_z):
    doc = scenario_doc(ALLEGRO)
    doc['object'] = {'shape': shape, 'size': size, 'mass': 0.2}
    sim = build_model(parse_scenario(doc, CONFIG))
    m = sim.model
    assert m.body_mass[sim.object_body] == pytest.approx(0.2)
    assert m.body_inertia[sim.object_body][2] == pytest.approx(inertia_z, rel=1e-9)


def test_refusals_name_the_field():
    with pytest.raises(InputError, match=r"^object: .*needs the scenario's object"):
        build_model(load_scenario(PLANAR))
    doc = scenario_doc(PLANAR)
    doc['object'] = {'shape': 'sphere', 'size': [0.035], 'mass': 0.1}
    with pytest.raises(InputError, match=r'^gravity: '):
        build_model(parse_scenario(copy.deepcopy(doc), CONFIG))
    doc['gravity'] = [0.0, -9.81, 0.0]
    # The planar hand's tips are frames without collision geometry: nothing to touch with.
    with pytest.raises(InputError, match=r'^grasp.contacts\[0\].link: .*no collision geometry'):
        build_model(parse_scenario(doc, CONFIG))
    with pytest.raises(InputError, match=r'^hand.urdf: '):
        build_model(load_scenario(ALLEGRO), urdf_xml="<robot><link name='a'>")


def test_the_planned_contacts_touch_the_object_at_the_grasp(allegro_sim, allegro):
    """
    The bundled grasp's tips are tangent to the ball.

    MuJoCo finds one contact on each, within 0.1 mm of the planned point, normal within 1
    degree.
    """
    m = allegro_sim.model
    d = mujoco.MjData(m)
    d.qpos[allegro_sim.qpos_adr] = allegro.q[allegro.hand.idx_q]
    m.geom_margin[:] = 1e-4  # report touching pairs even at zero penetration
    try:
        mujoco.mj_forward(m, d)
    finally:
        m.geom_margin[:] = 0.0
    maps = GraspSetup.maps(allegro)
    for i, body in enumerate(allegro_sim.contact_bodies):
        found = [c for c in d.contact[:d.ncon]
                 if body in (m.geom_bodyid[c.geom1], m.geom_bodyid[c.geom2])]
        assert len(found) == 1
        c = found[0]
        sign = 1.0 if m.geom_bodyid[c.geom2] == allegro_sim.object_body else -1.0
        assert np.linalg.norm(c.pos - maps.positions[i]) < 1e-4
        assert sign * c.frame[:3] @ maps.rotations[i][:, 2] > np.cos(np.radians(1.0))
