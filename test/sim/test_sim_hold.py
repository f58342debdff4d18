# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The certified torques hold the ball in MuJoCo; the same impedance without them drops it."""

from conftest import ALLEGRO
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.sim.hold import certified_torques, hold, HoldSettings
from grasp_torque_opt.sim.model import build_model
from grasp_torque_opt.sim.render import render_grasp
from grasp_torque_opt.sim.simulator import HandSim
import numpy as np
import pytest

#: The bundled Allegro grasp's impedance in the driver (docs/simulation.md).
IMPEDANCE = {'kp': 1.0, 'kd': 0.01}


@pytest.fixture(scope='module')
def scenario():
    return load_scenario(ALLEGRO)


@pytest.fixture(scope='module')
def held(scenario):
    return hold(scenario, HoldSettings(**IMPEDANCE, duration=2.0))


def test_certified_torques_hold_the_ball_within_a_millimetre(held):
    assert held.held, held.reason
    assert held.time == pytest.approx(2.0) and held.max_drift < 1e-3
    assert np.degrees(held.rotation) < 1.0
    assert all(c.touching for c in held.contacts) and held.unplanned_force < 1e-6


def test_the_same_impedance_without_feedforward_drops_it(scenario):
    r = hold(scenario, HoldSettings(**IMPEDANCE, duration=1.0, feedforward=0.0))
    assert not r.held and r.max_drift > 10e-3, r.reason
    assert 'fell' in r.reason


def test_simulated_contact_forces_equal_the_certified_wrenches(held, scenario):
    for c in held.contacts:
        assert c.force_error < 0.03, (c.link, c.predicted, c.simulated)
    # Independent of the solution: the simulated contact forces carry the ball's weight.
    total = sum(held_force(c) for c in held.contacts)
    weight = scenario.object.mass * scenario.gravity
    np.testing.assert_allclose(total, -weight, atol=0.01 * np.linalg.norm(weight))


def held_force(contact):
    """Return the simulated contact force in base axes, from the contact-frame wrench."""
    return contact.rotation @ contact.simulated[:3]


def test_a_picture_is_written(tmp_path, scenario):
    setup, maps, sol, g = certified_torques(scenario)
    hsim = HandSim(build_model(scenario), setup.q[setup.hand.idx_q], **IMPEDANCE)
    hsim.command = sol.tau + g
    hsim.step(100)
    path = render_grasp(hsim, tmp_path / 'grasp.png', size=(320, 240))
    data = path.read_bytes()
    assert data[:8] == b'\x89PNG\r\n\x1a\n'
    assert int.from_bytes(data[16:20], 'big') == 320 and int.from_bytes(data[20:24], 'big') == 240
