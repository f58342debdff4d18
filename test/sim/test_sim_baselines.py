# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause
"""The baselines: a preset that squeezes along the normals, a position-controlled squeeze."""

from conftest import ALLEGRO
from grasp_torque_opt.core.grasp_maps import compute_grasp_maps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.sim.baselines import (
    Preset,
    PRESET_LEVELS,
    Squeeze,
    squeeze_pattern,
    tune_preset,
)
from grasp_torque_opt.sim.episode import EpisodeSettings, run_episode, simulated
from grasp_torque_opt.sim.hold import gravity_torque
import numpy as np
import pytest


@pytest.fixture(scope='module')
def scenario():
    return load_scenario(ALLEGRO)


@pytest.fixture(scope='module')
def setup(scenario):
    return GraspSetup.from_scenario(scenario)


def test_the_preset_presses_every_contact_along_its_normal_at_least_at_its_level(
        scenario, setup):
    pattern = squeeze_pattern(setup)
    assert pattern.min() == pytest.approx(1.0, abs=1e-9)
    # No other pattern of at-least-1 normal forces pushes the object less (a few tried).
    maps = setup.maps()
    net = maps.G[:3, 2::4]
    rng = np.random.default_rng(0)
    for _ in range(200):
        other = 1.0 + rng.exponential(1.0, pattern.size)
        assert np.linalg.norm(net @ other) >= np.linalg.norm(net @ pattern) - 1e-9
    preset = Preset(setup, scenario.gravity, 0.8)
    reading = setup.q[setup.hand.idx_q]
    wrenches = np.zeros((pattern.size, 4))
    wrenches[:, 2] = 0.8 * pattern
    expected = maps.J.T @ wrenches.ravel() + gravity_torque(setup, setup.q, scenario.gravity)
    np.testing.assert_allclose(preset(reading), expected, atol=1e-12)
    assert np.all(np.abs(Preset(setup, scenario.gravity, 100.0)(reading)) <= 0.7)


def test_the_squeeze_commands_each_contact_its_depth_inside_the_object(setup):
    squeeze = Squeeze(setup, np.zeros(3), depth=3e-3)
    q = setup.q.copy()
    q[setup.hand.idx_q] = squeeze.target
    before = setup.maps()
    after = compute_grasp_maps(setup.hand, q, setup.contacts, setup.object_origin)
    for i in range(len(setup.contacts)):
        moved = after.positions[i] - before.positions[i]
        inward = before.rotations[i][:, 2]
        assert moved @ inward == pytest.approx(3e-3, rel=0.15)  # first order in the depth
        assert np.linalg.norm(moved - (moved @ inward) * inward) < 0.5e-3
    np.testing.assert_array_equal(squeeze.reference(np.zeros(16)), squeeze.target)


def test_the_tuned_preset_is_the_level_of_least_drift_and_both_baselines_report(scenario):
    tuned = tune_preset(scenario, kp=1.0, kd=0.01, duration=0.3)
    assert tuned.level in PRESET_LEVELS
    settings = EpisodeSettings(duration=0.3)
    for level in (PRESET_LEVELS[0], PRESET_LEVELS[-1]):
        setup, rig = simulated(scenario, settings)
        other = run_episode(rig, Preset(setup, scenario.gravity, level), settings)
        assert other.max_drift >= tuned.drift
    setup, rig = simulated(scenario, settings)
    squeeze = Squeeze(setup, scenario.gravity)
    report = run_episode(rig, squeeze, settings, squeeze.reference)
    np.testing.assert_allclose(rig.q_ref, squeeze.target)
    assert report.mean_effort > 0 and report.time > 0
