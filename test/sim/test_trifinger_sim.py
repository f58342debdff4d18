# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The simulated TriFinger holds its cube with the node's torques, and only with them.

In simulated time (MuJoCo, reproducible), without ROS: the node's cycle
(:func:`grasp_torque_opt.ros.sim_compare.node_controller`, gravity compensation on, the
scenario's friction margin) drives the bundled config/trifinger.yaml. Each holding case
has a twin that must drop the cube: the fingers' gravity compensation alone, the node
told a cube three times lighter than the simulated one, the shake without the IMU.
"""

from conftest import CONFIG
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.ros.sim_compare import node_controller
from grasp_torque_opt.sim.base_motion import BaseMotion, STANDARD_GRAVITY
from grasp_torque_opt.sim.episode import EpisodeSettings, run_episode, simulated
from grasp_torque_opt.sim.hold import gravity_torque
from grasp_torque_opt.sim.rig import Disturbances
import numpy as np
import pytest

SCENARIO = load_scenario(CONFIG / 'trifinger.yaml')
MARGIN = 0.3   # the scenario's friction.margin


def episode(duration=3.0, imu=False, gravity_only=False, **fields):
    settings = EpisodeSettings(duration=duration, **fields)
    setup, rig = simulated(SCENARIO, settings)
    q = setup.q.copy()

    def compensation(reading):
        q[setup.hand.idx_q] = reading
        return gravity_torque(setup, q, SCENARIO.gravity)
    command = compensation if gravity_only else node_controller(
        setup, SCENARIO, rig, inputs=imu, efforts=False, margin=MARGIN)
    return run_episode(rig, command, settings)


def test_the_nodes_torques_hold_the_cube_for_3_s():
    report = episode()
    assert report.held and report.time == pytest.approx(3.0), report
    assert report.max_drift < 1e-3 and np.degrees(report.max_rotation) < 2.0, report


def test_gravity_compensation_alone_drops_the_cube():
    report = episode(duration=1.0, gravity_only=True)
    assert report.fell, report


def test_torques_for_a_cube_three_times_too_light_drop_it():
    report = episode(duration=1.0, mass_scale=3.0)
    assert report.fell, report


def shake(axis):
    a = np.zeros(3)
    a['xyz'.index(axis)] = 1.0
    return Disturbances(motion=BaseMotion(shake_amplitude=STANDARD_GRAVITY,
                                          shake_frequency=1.0, shake_axis=a))


@pytest.mark.parametrize('axis', ['x', 'y', 'z'])
def test_a_1_g_1_hz_shake_is_held_with_the_imu(axis):
    # The TriFinger's base is fixed (its params file has the IMU off); a shaken one needs
    # the base's acceleration in its load, as the palm IMU gives it.
    report = episode(imu=True, disturbances=shake(axis))
    assert report.held and np.degrees(report.max_rotation) < 2.0, report


def test_the_same_shake_drops_the_cube_without_the_imu():
    report = episode(duration=1.5, disturbances=shake('z'))
    assert not report.held, report
