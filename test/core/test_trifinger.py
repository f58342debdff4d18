# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The bundled TriFinger: its URDF is the script's output, its cube grasp is certified."""

import importlib.util

from conftest import CONFIG, ROOT
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import example_robot_data_dir
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.sim.hold import certified_torques
from independent import _f_space, assert_holds, lp_capacity, lp_feasible
import numpy as np
import pinocchio as pin
import pytest
from scipy.optimize import minimize
import yaml

TRIFINGER = CONFIG / 'trifinger.yaml'
TIP_RADIUS = 0.0095   # m, the tip of finger_edu's lower_link.stl (scripts/make_trifinger_urdf.py)
HALF_EDGE = 0.0325    # m, the RRC cube's 65 mm edges


@pytest.fixture(scope='module')
def scenario():
    return load_scenario(TRIFINGER)


def test_the_shipped_urdf_is_the_scripts_output():
    spec = importlib.util.spec_from_file_location('make_trifinger_urdf',
                                                  ROOT / 'scripts' / 'make_trifinger_urdf.py')
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    source = (example_robot_data_dir() / script.SOURCE).read_text()
    assert (ROOT / 'urdf' / 'trifinger.urdf').read_text() == script.trifinger(source)


def test_nine_actuated_joints_at_120_degrees(scenario):
    setup = GraspSetup.from_scenario(scenario)
    hand = setup.hand
    assert hand.m == 9
    np.testing.assert_allclose(hand.torque_limits, 0.36)
    model, data = hand.model, hand.model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    bases = [data.oMf[model.getFrameId(f'finger_base_link_{a}')] for a in (0, 120, 240)]
    for k, base in enumerate(bases):
        # Each finger base 0.283 m up, 0.0455 m from the axis, turned by -120 k degrees.
        np.testing.assert_allclose(base.translation[2], 0.283)
        np.testing.assert_allclose(np.hypot(*base.translation[:2]), 0.0455)
        turn = -np.radians(120 * k)
        np.testing.assert_allclose(base.rotation @ [1, 0, 0], [np.cos(turn), np.sin(turn), 0],
                                   atol=1e-12)


def test_the_contacts_lie_on_the_tip_spheres_and_the_cube_faces(scenario):
    # Independent of the package's maps: the tip centres from Pinocchio at the grasp.
    setup = GraspSetup.from_scenario(scenario)
    model, data = setup.hand.model, setup.hand.model.createData()
    pin.framesForwardKinematics(model, data, setup.q)
    centre = np.asarray(scenario.object_origin, dtype=float)
    for contact in scenario.contacts:
        tip = data.oMf[model.getFrameId(contact.link)]
        point = tip.act(np.asarray(contact.position, dtype=float))
        normal = np.asarray(contact.normal, dtype=float)
        # On the tip's sphere, where its inward normal leaves it...
        np.testing.assert_allclose(np.linalg.norm(point - tip.translation), TIP_RADIUS,
                                   atol=1e-5)
        np.testing.assert_allclose((point - tip.translation) / TIP_RADIUS, normal, atol=2e-3)
        # ... on the face of the cube that the normal enters, inside its edges.
        local = point - centre
        np.testing.assert_allclose(local @ normal, -HALF_EDGE, atol=1e-5)
        assert np.all(np.abs(local) <= HALF_EDGE + 1e-5), local   # points written to 10 um
    q = setup.q[setup.hand.idx_q]
    lower = setup.hand.model.lowerPositionLimit[setup.hand.idx_q]
    upper = setup.hand.model.upperPositionLimit[setup.hand.idx_q]
    assert np.all((q > lower + 0.1) & (q < upper - 0.1)), q


def sum_of_squares_minimum(setup, maps):
    """Return min ||J^T f||^2 over the planned polygon cones and limits, by SciPy's SLSQP."""
    S, b, lim, off = _f_space(setup, maps)
    JT = maps.J.T
    f0 = np.tile([0.0, 0.0, 1.0, 0.0], maps.p)
    constraints = [{'type': 'eq', 'fun': lambda f: maps.G @ f + setup.external_wrench},
                   {'type': 'ineq', 'fun': lambda f: b - S @ f},
                   {'type': 'ineq', 'fun': lambda f: lim - np.abs(JT @ f + off)}]
    res = minimize(lambda f: np.sum((JT @ f) ** 2), f0, jac=lambda f: 2 * JT.T @ (JT @ f),
                   constraints=constraints, method='SLSQP', options={'ftol': 1e-14,
                                                                     'maxiter': 500})
    assert res.success, res.message
    return res.fun


def test_the_grasp_is_certified_optimal_with_a_useful_capacity(scenario):
    setup, maps, sol, g = certified_torques(scenario)
    assert sol.status == 'optimal', sol.status
    assert lp_feasible(setup, maps)
    assert_holds(setup, maps, sol.tau, sol.wrenches)
    # The same minimum from SciPy's SLSQP on the written-out problem.
    np.testing.assert_allclose(np.sum(sol.tau ** 2), sum_of_squares_minimum(setup, maps),
                               rtol=1e-4)
    # With finger gravity compensation, the whole command stays within 60% of 0.36 N m.
    assert np.max(np.abs(sol.tau + g)) < 0.6 * 0.36
    # The cube's weight twice over (a 1 g shake along z) within the planned cones and limits.
    alpha, _ = lp_capacity(setup, maps, setup.external_wrench)
    assert alpha > 2.0, alpha


def test_the_node_and_controllers_files_match_the_scenario(scenario):
    params = yaml.safe_load((CONFIG / 'trifinger_node.yaml').read_text())['/**']
    params = params['ros__parameters']
    assert (CONFIG / params['scenario']).resolve() == TRIFINGER.resolve()
    assert params['gravity_compensation'] is True and params['imu']['enabled'] is False
    assert params['torque_limits'] == [0.36] * 9
    controllers = yaml.safe_load((CONFIG / 'trifinger_controllers.yaml').read_text())
    assert controllers['effort_controller']['ros__parameters']['joints'] == scenario.joints
