# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The IMU's cross-checks (control/motion.py, ImuTracker.cross_checked) on the node's cycle.

A still hand holding the Allegro's ball: every command is checked at the TRUE grasp (the
scenario's gravity +x): the contact wrenches J^-T (tau - g_true(q)), g_true from
Pinocchio under the true gravity, must lie in the exact soft-finger cone.
"""

import contextlib
import dataclasses

from conftest import ALLEGRO
from cycle_inputs import joint_state
from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.control.inputs.imu import ImuReading
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.parameters.generated import CycleConfig
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.resources import find_config
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.ros.node.grasp_source import load_of_gravity
import numpy as np
import pinocchio as pin
import pytest

SCENARIO = load_scenario(find_config('allegro_right.yaml'))
G = np.asarray(SCENARIO.gravity, dtype=float)  # +x, palm down
STILL = -G  # what a still hand's accelerometer reads


def controller(**config):
    setup = GraspSetup.from_file(ALLEGRO)
    ctrl = TorqueController(dataclasses.replace(setup, hand=dataclasses.replace(setup.hand)),
                            CycleConfig(gravity_compensation=True, gravity=tuple(G),
                                        cycle_budget=1.0, **config))
    ctrl.load_of_gravity = load_of_gravity(SCENARIO)
    return ctrl


def true_wrenches(setup, command):
    """Give the contact wrenches a command exerts on the still hand under the true gravity."""
    model = setup.hand.model.copy()
    model.gravity.linear = G
    g = pin.computeGeneralizedGravity(model, model.createData(), setup.q)[setup.hand.idx_v]
    maps = setup.maps()
    return np.linalg.solve(maps.J.T, command - g).reshape(-1, 4)


def in_exact_cone(w, friction, tol=1e-6):
    return bool(np.all(np.hypot(w[:, 0], w[:, 1]) / friction.mu1 + np.abs(w[:, 3]) / friction.mu2
                       <= w[:, 2] + tol))


def drive(ctrl, force, omega, n_states=40, imu_per_state=5, t0=0.0):
    """Give IMU readings at 1 kHz and a joint state every ``imu_per_state``; the results."""
    names, pos = joint_state(ctrl.setup)
    t, results, refused = t0, [], 0
    for k in range(n_states):
        for j in range(imu_per_state):
            t += 1e-3
            cycles = ctrl.counters.cycles
            try:
                ctrl.take('imu', ImuReading('', force(t), omega(t)), t)
            except InputError:
                refused += 1
            assert ctrl.counters.cycles == cycles  # an IMU message never runs a cycle
        ctrl.take('joint_states', JointStateReading(names, pos), t)
        results.append(ctrl.cycle(t))
    return results, refused, t


def test_a_still_hand_told_19g_sideways_refuses_the_imu_and_never_pulls():
    ctrl = controller()
    zero = lambda t: np.zeros(3)  # noqa: E731
    _, refused, t = drive(ctrl, lambda t: STILL, zero, n_states=10)
    assert refused == 0
    # The spoof: 1.9 g sideways (apparent gravity [0, 0, 18.64]) on a still hand.
    spoof = np.array([0.0, 0.0, -18.64])
    results, refused, _ = drive(ctrl, lambda t: spoof, zero, t0=t)
    assert refused == 200
    assert 'imu.linear_acceleration' in ctrl.last_rejection
    assert 'imu.max_arm_acceleration' in ctrl.store.imu.refused
    assert 'imu stale' in ctrl.solving.imu_state  # then the scenario's gravity
    for r in results:
        assert r.kind == 'solution'
        assert in_exact_cone(true_wrenches(ctrl.setup, r.command), ctrl.setup.friction)


def test_gravity_turning_with_the_base_is_accepted_and_without_rotation_refused():
    # The base turns about z at 1 rad/s: gravity turns in its axes at that rate. With the
    # default bound (about 2 g) no orientation at rest is refused (|g_app - g_ref| <= 2 g):
    # an arm stated to accelerate at most 0.5 g shows the direction rule.
    turn = lambda t: STILL @ pin.exp3(np.array([0.0, 0.0, 1.0 * t]))  # noqa: E731
    arm = {'imu_max_arm_acceleration': 0.5 * 9.80665}
    ctrl = controller(**arm)
    _, refused, _ = drive(ctrl, turn, lambda t: np.array([0.0, 0.0, 1.0]), n_states=400)
    assert refused == 0, ctrl.last_rejection
    # The same turn with a gyro saying the base is still: refused once it is past the bound.
    ctrl = controller(**arm)
    _, refused, _ = drive(ctrl, turn, lambda t: np.zeros(3), n_states=400)
    assert refused > 0 and 'imu.max_arm_acceleration' in ctrl.last_rejection


@pytest.mark.parametrize('axis', [0, 1, 2])
def test_the_2g_shakes_of_the_robustness_grid_pass(axis):
    # bench/robustness.py: 2 g at 1 Hz along each base axis, a translation (no rotation).
    e = np.eye(3)[axis]
    shake = lambda t: 2.0 * 9.80665 * np.sin(2 * np.pi * t) * e - G  # noqa: E731
    ctrl = controller()
    _, refused, _ = drive(ctrl, shake, lambda t: np.zeros(3), n_states=200)
    assert refused == 0, ctrl.last_rejection


def test_angular_rate_chatter_is_refused_and_every_joint_state_gets_its_command():
    # The issue: +-29 rad/s at 1 kHz (under imu.max_angular_velocity); about y, every
    # other cycle's grasp was infeasible (the filtered derivative's inertial wrench).
    ctrl = controller()
    zero = lambda t: np.zeros(3)  # noqa: E731
    still, _, t = drive(ctrl, lambda t: STILL, zero, n_states=20)
    chatter = lambda t: np.array([0.0, 29.0 if round(t * 1e3) % 2 else -29.0, 0.0])  # noqa: E731
    results, refused, _ = drive(ctrl, lambda t: STILL, chatter, n_states=200, t0=t)
    assert [r.kind for r in still + results] == ['solution'] * 220
    assert refused == 1000 and 'imu.max_angular_acceleration' in ctrl.last_rejection
    assert not np.any(ctrl.store.imu.alpha)  # the filtered derivative never saw it


def test_after_chatter_the_imu_is_refused_until_its_rate_has_settled():
    # A lost reading makes two chatter readings in a row agree: still refused, until the
    # rate has kept imu.max_angular_acceleration for imu.timeout_bounds' upper bound.
    ctrl = controller()
    settle = ctrl.config.imu_timeout_bounds[1]
    spin = np.array([0.0, 29.0, 0.0])
    verdicts, t = [], 0.0
    for w in [np.zeros(3)] * 3 + [spin] * 80:  # +-29 rad/s with every -29 lost
        t += 1e-3
        try:
            ctrl.take('imu', ImuReading('', STILL, w), t)
            verdicts.append(True)
        except InputError as e:
            verdicts.append(False)
            why = str(e)
    n = round(settle / 1e-3)
    assert verdicts[:3] == [True] * 3 and not any(verdicts[3:3 + n])
    assert 'refused until the rate has kept it' in why
    assert all(verdicts[4 + n:])  # a steady rate, consistent again: a real spin


def test_a_noisy_gyro_delivered_in_bursts_is_not_taken_for_chatter():
    # Five readings 1 ms apart at the IMU, received within 50 us (a middleware's burst):
    # a gyro's noise of 0.01 rad/s between them is 200 rad/s^2 over 50 us, not over 1 ms.
    ctrl = controller()
    rng = np.random.default_rng(3)
    t = 0.0
    for burst in range(60):
        t += 5e-3
        if burst == 20:  # the readings' spacing learned (the first may be refused)
            ctrl.counters.rejected['imu'] = 0
        for j in range(5):
            noise = rng.normal(0.0, 0.01, 3)
            with contextlib.suppress(InputError):
                ctrl.take('imu', ImuReading('', STILL, noise), t + 1e-5 * j)
    assert ctrl.counters.rejected.get('imu', 0) == 0
    assert ctrl.inputs.motion_time == t + 4e-5  # the last reading is the one in use
