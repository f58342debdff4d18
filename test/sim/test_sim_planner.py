# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The planner's numbers on physics.

A friction margin holds where the minimum-effort torques slip, and the ball falls just
above the mass the capacity LP predicts.
"""

import dataclasses

from conftest import ALLEGRO
from grasp_torque_opt.core.scenario import load_scenario, weight_wrench
from grasp_torque_opt.methods.capacity import load_capacity
from grasp_torque_opt.sim.hold import certified_torques, hold, HoldSettings
from grasp_torque_opt.sim.model import SimSettings
import pytest


@pytest.fixture(scope='module')
def scenario():
    return load_scenario(ALLEGRO)


def with_mass(s, mass):
    obj = dataclasses.replace(s.object, mass=mass)
    return dataclasses.replace(s, object=obj, external_wrench=s.extra_wrench + weight_wrench(
        obj, s.gravity, s.object_origin))


def test_a_margin_holds_at_the_friction_it_plans_for(scenario):
    """Planned with k = 0.25, simulated with mu/(1 + k): held; the unmargined torques slip."""
    k = 0.25
    sim = SimSettings(mu_tangential=scenario.friction.mu1 / (1 + k),
                      mu_torsional=scenario.friction.mu2 / (1 + k))
    settings = HoldSettings(kp=0.3, kd=0.01, duration=1.0)
    margined = dataclasses.replace(scenario, friction=dataclasses.replace(scenario.friction,
                                                                          margin=k))
    assert hold(margined, settings, sim).held
    plain = hold(scenario, settings, sim)
    assert not plain.held and plain.max_drift > 1e-3


def test_the_ball_falls_just_above_the_capacity(scenario):
    setup, maps, _, _ = certified_torques(scenario)  # g(q0) as the offset, as the node
    cap = load_capacity(setup, maps)
    m_star = cap.value * scenario.object.mass
    plan = with_mass(scenario, 0.999 * m_star)
    settings = HoldSettings(kp=1.0, kd=0.01, duration=1.0)
    assert hold(plan, settings).held
    assert not hold(plan, settings, SimSettings(mass=1.05 * m_star)).held
    # Above the capacity the optimizer has no torques at all.
    assert not certified_torques(with_mass(scenario, 1.01 * m_star))[2].optimal
