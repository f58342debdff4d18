# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause
"""The base's motion as apparent gravity: the palm IMU reads it, the ball moves with it."""

from conftest import ALLEGRO, CONFIG
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.sim.base_motion import BaseMotion, STANDARD_GRAVITY
from grasp_torque_opt.sim.episode import EpisodeSettings, run_episode, simulated
from grasp_torque_opt.sim.hold import certified_torques, gravity_torque
from grasp_torque_opt.sim.rig import Disturbances
import numpy as np
import pytest


@pytest.fixture(scope='module')
def scenario():
    return load_scenario(ALLEGRO)


def node_like(scenario):
    """Return the node's command as hold() makes it: certified tau plus g(q) at the reading."""
    setup, _, sol, _ = certified_torques(scenario)
    q = setup.q.copy()

    def command(reading):
        q[setup.hand.idx_q] = reading
        return sol.tau + gravity_torque(setup, q, scenario.gravity)
    return command


def test_static_acceleration_and_shake_from_release_on():
    motion = BaseMotion(accel=np.array([1.0, 2.0, 3.0]), shake_amplitude=2.0,
                        shake_frequency=1.0, shake_axis=np.array([0.0, 0.0, 1.0]))
    np.testing.assert_array_equal(motion.acceleration(-0.1), np.zeros(3))
    np.testing.assert_allclose(motion.acceleration(0.25), [1.0, 2.0, 5.0])
    np.testing.assert_allclose(motion.acceleration(0.75), [1.0, 2.0, 1.0])
    np.testing.assert_allclose(motion.apparent_gravity([9.81, 0, 0], 0.25), [8.81, -2, -5])
    with pytest.raises(ValueError, match='shake_axis must be a unit vector'):
        BaseMotion(shake_axis=np.array([1.0, 1.0, 0.0]))
    with pytest.raises(ValueError, match='shake_frequency must be finite and >= 0'):
        BaseMotion(shake_frequency=-1.0)


@pytest.mark.parametrize('accel', [[0.5, 0, 0], [0, -0.5, 0], [0, 0, 2.0]])
def test_the_imu_reads_minus_gravity_at_rest_and_a_minus_g_moving(scenario, accel):
    a = STANDARD_GRAVITY * np.array(accel)
    settings = EpisodeSettings(disturbances=Disturbances(motion=BaseMotion(accel=a)))
    _, rig = simulated(scenario, settings)
    rig.step(5)
    force, omega = rig.imu()
    # An accelerometer at rest reads the opposite of gravity (palm down: gravity along +x).
    np.testing.assert_allclose(force, -np.asarray(scenario.gravity), atol=1e-9)
    np.testing.assert_allclose(omega, 0.0, atol=1e-12)
    rig.release()
    rig.step(5)
    force, omega = rig.imu()
    np.testing.assert_allclose(force, a - scenario.gravity, atol=1e-9)
    np.testing.assert_allclose(omega, 0.0, atol=1e-12)


@pytest.mark.parametrize('name', ['g1_right.yaml', 'ability_right.yaml'])
def test_a_hand_inside_a_robot_reads_its_imu_in_its_own_palm_frame(name):
    # hand.base_link's axes, not its body's principal axes of inertia (MuJoCo's
    # mjOBJ_BODY frame, which turned the G1's reading of 9.81 along x into 9.79 along z).
    scenario = load_scenario(CONFIG / name)
    a = STANDARD_GRAVITY * np.array([0.3, -0.5, 0.7])
    settings = EpisodeSettings(disturbances=Disturbances(motion=BaseMotion(accel=a)))
    _, rig = simulated(scenario, settings)
    rig.step(5)
    np.testing.assert_allclose(rig.imu()[0], -np.asarray(scenario.gravity), atol=1e-6)
    rig.release()
    rig.step(5)
    force, omega = rig.imu()
    np.testing.assert_allclose(force, a - scenario.gravity, atol=1e-6)
    np.testing.assert_allclose(omega, 0.0, atol=1e-9)


@pytest.mark.parametrize('axis', [0, 2])
@pytest.mark.parametrize('sign', [1.0, -1.0])
def test_the_ball_moves_against_the_bases_acceleration(scenario, axis, sign):
    # In the accelerating hand the ball feels g - a: 2 g along an axis drops it, backwards.
    a = np.zeros(3)
    a[axis] = sign * 2 * STANDARD_GRAVITY
    settings = EpisodeSettings(duration=0.5, disturbances=Disturbances(
        motion=BaseMotion(accel=a)))
    _, rig = simulated(scenario, settings)
    report = run_episode(rig, node_like(scenario), settings)
    assert not report.held
    moved = rig.object_pose()[0] - rig.release_pose[:3]
    assert moved @ -a / np.linalg.norm(a) > 0.5 * np.linalg.norm(moved), moved


def test_without_acceleration_the_same_ball_is_held(scenario):
    settings = EpisodeSettings(duration=0.5)
    _, rig = simulated(scenario, settings)
    report = run_episode(rig, node_like(scenario), settings)
    assert report.held and report.max_drift < 0.1e-3, report
