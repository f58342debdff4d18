# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The simulated drivers: each command interface holds the shaken ball, a wrong constant drops it.

In simulated time, without ROS: the node's own cycle (ros/sim_compare.node_controller,
configured as the bundled params configure it, its IMU and efforts on) converts each
certified command with its command interface, and the rig's driver model
(sim/drivers) turns the message into joint torques every physics step: a position
servo of stiffness 1 N m/rad, a current-mode motor, a hybrid PD. The Allegro's ball on
the 1 g, 1 Hz shake along x, y and z. Told 3 K (position) or 2 k_t (current), the node
makes a third or a half of the certified torque, and the ball falls: so the tests can
fail.
"""

from grasp_torque_opt.core.resources import find_config
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.ros.sim_compare import node_controller
from grasp_torque_opt.sim.base_motion import BaseMotion, STANDARD_GRAVITY
from grasp_torque_opt.sim.drivers import attach, DriverSettings, node_overrides, SimDriver
from grasp_torque_opt.sim.episode import EpisodeSettings, run_episode, simulated
from grasp_torque_opt.sim.rig import Disturbances
import numpy as np
import pytest

SCENARIO = load_scenario(find_config('allegro_right.yaml'))
AXES = {'x': (1.0, 0.0, 0.0), 'y': (0.0, 1.0, 0.0), 'z': (0.0, 0.0, 1.0)}
#: The node's parameter -> its CycleConfig field.
FIELDS = {'command_interface': 'command_interface', 'position.stiffness': 'position_stiffness',
          'current.torque_constant': 'current_torque_constant',
          'current.gear_ratio': 'current_gear_ratio', 'current.limit': 'current_limit',
          'hybrid.kp': 'hybrid_kp', 'hybrid.kd': 'hybrid_kd'}


def episode(kind: str, axis: str, told: dict | None = None, duration: float = 3.0):
    """Run the ball on the shake through a driver, the node told ``told`` over its constants."""
    motion = BaseMotion(shake_amplitude=STANDARD_GRAVITY, shake_frequency=1.0,
                        shake_axis=np.array(AXES[axis]))
    settings = EpisodeSettings(kp=1.0, kd=0.01, duration=duration,
                               disturbances=Disturbances(motion=motion))
    setup, rig = simulated(SCENARIO, settings)
    driver_settings = DriverSettings(kind=kind, kp=1.0, kd=0.01)
    driver = attach(rig, driver_settings)
    params = {**node_overrides(driver_settings), **(told or {})}
    config = {FIELDS[k]: tuple(v) if isinstance(v, list) else v for k, v in params.items()}
    command = node_controller(setup, SCENARIO, rig, inputs=True, commands=config)
    ctrl = command.controller
    published = []

    def drive(reading):
        command(reading)
        result = ctrl.last
        if result is not None and result.command is not None and result.output is not None:
            out = result.output
            assert out.interface == kind and out.well_formed(setup.hand.m)
            published.append(out)
            driver.receive(out.values, out.position, out.velocity)
        return None  # the driver applies it, every physics step

    report = run_episode(rig, drive, settings)
    return report, ctrl, published


@pytest.mark.parametrize('axis', sorted(AXES))
@pytest.mark.parametrize('kind', ['effort', 'position', 'current', 'hybrid'])
def test_each_interface_holds_the_shaken_ball(kind, axis):
    report, ctrl, published = episode(kind, axis)
    # The target of test_sim_node_inputs.py: within 2 mm for the whole 3 s, barely turned.
    assert report.max_drift < 2e-3, report
    assert report.time >= 3.0 - 1e-9 and not report.fell, report
    assert np.degrees(report.max_rotation) < 2.0, report
    assert ctrl.counters.faults == 0 and len(published) > 700  # 250 Hz for 3.3 s


@pytest.mark.parametrize('kind, told', [
    ('position', {'position.stiffness': [3.0]}),       # the servo's K is 1 N m/rad
    ('current', {'current.torque_constant': [0.7]}),   # the motor's k_t is 0.35 N m/A
], ids=['position told 3 K', 'current told 2 k_t'])
def test_the_wrong_constant_drops_the_ball(kind, told):
    report, ctrl, published = episode(kind, 'y', told)
    assert report.fell, report
    assert ctrl.counters.faults == 0  # certified and published: the driver is not the node's


def test_the_driver_models_make_their_torques():
    q = np.array([0.1, -0.2])
    position = SimDriver(DriverSettings('position', kp=2.0, current_limit=1.0), 2)
    np.testing.assert_array_equal(position.torque(q), np.zeros(2))  # no command yet
    position.receive(np.array([0.15, 0.3]))
    # K (q_cmd - q) = [0.1, 1.0], the second clipped at k_t gear I_max = 0.35 N m.
    np.testing.assert_allclose(position.torque(q), [0.1, 0.35])
    current = SimDriver(DriverSettings('current', gear_ratio=2.0, current_limit=1.0), 2)
    current.receive(np.array([0.5, -3.0]))
    np.testing.assert_allclose(current.torque(q), [0.35, -0.7])  # k_t gear clip(I)
    hybrid = SimDriver(DriverSettings('hybrid', kp=2.0, kd=0.5), 2)
    hybrid.receive(np.array([0.05, 0.0]), np.array([0.1, 0.0]), np.array([0.0, 1.0]))
    # tau_ff + kp (q_des - q) + kd dq_des (MuJoCo's damping gives -kd qdot).
    np.testing.assert_allclose(hybrid.torque(q), [0.05, 0.4 + 0.5])


@pytest.mark.parametrize('fields, match', [
    ({'kind': 'torque'}, 'driver must be one of effort, position'),
    ({'kind': 'position', 'kp': 0.0}, 'kp must be > 0 for the position driver'),
    ({'current_limit': -1.0}, 'current_limit must be finite and > 0'),
])
def test_bad_driver_settings_are_refused(fields, match):
    with pytest.raises(ValueError, match=match):
        DriverSettings(**fields)


def test_the_node_is_told_the_drivers_constants():
    s = DriverSettings('current', torque_constant=0.2, gear_ratio=3.0, current_limit=1.5)
    assert node_overrides(s) == {'command_interface': 'current',
                                 'current.torque_constant': [0.2],
                                 'current.gear_ratio': [3.0], 'current.limit': [1.5]}
    assert node_overrides(DriverSettings('position', kp=0.8)) == {
        'command_interface': 'position', 'position.stiffness': [0.8]}
    assert node_overrides(DriverSettings()) == {'command_interface': 'effort'}
