# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause
"""The rig's disturbances move the physics the right way; its efforts are what it applies."""

from conftest import ALLEGRO
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.sim.episode import EpisodeSettings, run_episode, simulated
from grasp_torque_opt.sim.rig import Disturbances
import numpy as np
import pytest
from test_sim_base_motion import node_like


@pytest.fixture(scope='module')
def scenario():
    return load_scenario(ALLEGRO)


def episode(scenario, **settings):
    settings = EpisodeSettings(**{'duration': 0.5, **settings})
    _, rig = simulated(scenario, settings)
    return rig, run_episode(rig, node_like(scenario), settings)


def test_a_ball_three_times_heavier_than_planned_falls(scenario):
    rig, heavy = episode(scenario, mass_scale=3.0)
    assert rig.model.body_mass[rig.sim.object_body] == pytest.approx(3 * 0.15)
    assert heavy.fell and heavy.passed_at < 0.1, heavy
    _, nominal = episode(scenario, mass_scale=1.0)
    assert nominal.held, nominal


def test_the_object_sits_where_the_offset_puts_it_and_a_large_offset_drops_it(scenario):
    offset = (0.0, -3e-3, 0.0)
    _, rig = simulated(scenario, EpisodeSettings(object_offset=offset))
    np.testing.assert_allclose(rig.object_pose()[0],
                               np.asarray(scenario.object.position) + offset, atol=1e-12)
    _, small = episode(scenario, object_offset=(0.0, 0.0, 1e-3))
    assert small.held, small
    _, large = episode(scenario, object_offset=(0.0, -8e-3, 0.0))
    assert not large.held, large


def test_encoder_noise_is_on_the_reading_and_in_the_impedance(scenario):
    noise, kp = 5e-3, 1.0
    settings = EpisodeSettings(kp=kp, disturbances=Disturbances(joint_noise=noise, seed=3))
    _, rig = simulated(scenario, settings)
    errors = []
    for _ in range(200):
        before = rig.q
        rig.step()
        errors.append(rig.reading - before)
        # The impedance pulls towards q_ref from the noisy reading, not from q.
        np.testing.assert_allclose(rig.effort() - rig.command + rig.kd * rig.qdot,
                                   kp * (rig.q_ref - rig.reading), atol=1e-15)
    errors = np.array(errors)
    assert np.std(errors) == pytest.approx(noise, rel=0.05)
    assert abs(np.mean(errors)) < 0.1 * noise


def test_the_efforts_are_the_torques_mujoco_applied(scenario):
    settings = EpisodeSettings(kp=1.0, kd=0.01)
    _, rig = simulated(scenario, settings)
    command = node_like(scenario)
    rig.command = command(rig.reading)
    rig.release()
    efforts = []
    for _ in range(50):
        rig.step()
        # What MuJoCo got: the applied generalized force and its implicit damping -Kd qdot
        # (integrated at the velocity the step ends with).
        applied = rig.data.qfrc_applied[rig.sim.dof_adr] - rig.kd * rig.qdot
        np.testing.assert_allclose(rig.effort(), applied, atol=1e-15)
        efforts.append(rig.effort())
    assert rig.mean_effort() == pytest.approx(float(np.sqrt(np.mean(np.square(efforts)))),
                                              rel=1e-12)


def test_a_force_on_the_object_pushes_it_as_its_weight_does(scenario):
    """The fingers only carry their own weight: the ball falls; minus its weight floats it."""
    weight = scenario.object.mass * np.asarray(scenario.gravity)

    def run(force, duration, drift_limit=1e-3):
        settings = EpisodeSettings(duration=duration, object_force=force,
                                   drift_limit=drift_limit)
        setup, rig = simulated(scenario, settings)
        hand = setup.hand

        def own_weight(reading):  # g(q): the fingers neither sag nor squeeze
            q = setup.q.copy()
            q[hand.idx_q] = reading
            return hand.gravity_torques(hand.complete(q), scenario.gravity)
        start = rig.object_pose()[0]
        return run_episode(rig, own_weight, settings), rig.object_pose()[0] - start

    fell, _ = run((0.0, 0.0, 0.0), 0.3)
    assert not fell.held, fell
    floated, _ = run(tuple(-weight), 0.3)
    assert floated.held and floated.max_drift < 2e-4 and floated.max_rotation < 1e-2, floated
    # Twice the weight's opposite lifts it towards the palm (base -x).
    _, moved = run(tuple(-2 * weight), 0.1, drift_limit=1.0)
    assert moved[0] < -1e-3 and abs(moved[1]) < 0.5 * abs(moved[0]), moved
