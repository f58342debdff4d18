# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The node's cycle with its IMU and effort inputs on a disturbed simulated hand (MuJoCo).

In simulated time, without ROS: bench/robustness.py's node controller (the node's
TorqueController configured as the bundled params configure it), given the rig's palm
IMU and measured efforts at each joint state, or not. Each case also runs without the
input, and the ball must then be lost: so the test can fail.
"""

from pathlib import Path
import sys

from grasp_torque_opt.core.resources import find_config
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.sim.base_motion import BaseMotion, STANDARD_GRAVITY
from grasp_torque_opt.sim.episode import EpisodeSettings, run_episode, simulated
from grasp_torque_opt.sim.rig import Disturbances
import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'bench'))
from robustness import node_controller  # noqa: E402, I100

SCENARIO = load_scenario(find_config('allegro_right.yaml'))


def episode(inputs, margin=0.0, **fields):
    settings = EpisodeSettings(kp=0.3, duration=2.0, **fields)
    setup, rig = simulated(SCENARIO, settings)
    command = node_controller(setup, SCENARIO, rig, inputs, margin)
    return run_episode(rig, command, settings), command.controller


@pytest.mark.parametrize('scale, margin', [(1.3, 0.5), (1.1, 0.0)])
def test_a_heavier_ball_is_held_with_the_effort_estimate_and_lost_without(scale, margin):
    held, ctrl = episode(True, margin, mass_scale=scale)
    assert held.max_drift < 2e-3 and held.time >= 2.0 - 1e-9, held  # the target
    lost, _ = episode(False, margin, mass_scale=scale)
    assert lost.fell, lost
    # In the static hold, the estimate is the simulated ball's weight (analytic, along the
    # scenario's gravity +x), within a few percent.
    weight = scale * SCENARIO.object.mass * np.asarray(SCENARIO.gravity)
    estimate = ctrl.solving.effort_load.estimate
    assert np.linalg.norm(estimate[:3] - weight) < 0.05 * np.linalg.norm(weight), estimate
    # The planned load followed it: the scenario's weight plus the correction.
    assert np.linalg.norm(ctrl.solving.load[:3] - weight) < 0.05 * np.linalg.norm(weight)


@pytest.mark.parametrize('motion', [
    BaseMotion(shake_amplitude=STANDARD_GRAVITY, shake_frequency=1.0,
               shake_axis=np.array([0.0, 1.0, 0.0])),
    BaseMotion(shake_amplitude=STANDARD_GRAVITY, shake_frequency=1.0,
               shake_axis=np.array([0.0, 0.0, 1.0]))], ids=['shake y', 'shake z'])
def test_a_shaking_hand_holds_the_ball_with_the_imu_and_drops_it_without(motion):
    held, ctrl = episode(True, disturbances=Disturbances(motion=motion))
    assert held.max_drift < 2e-3 and held.time >= 2.0 - 1e-9, held  # the target
    assert np.degrees(held.rotation) < 2.0, held
    assert ctrl.solving.imu_state == ''  # the IMU was in use
    lost, _ = episode(False, disturbances=Disturbances(motion=motion))
    assert lost.fell, lost
