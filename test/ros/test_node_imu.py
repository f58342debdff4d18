# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The imu input (imu.enabled): the apparent gravity -R f in g(q) and the load, bad readings.

Each command is checked against an independent solve: the scenario's ball under the
analytic apparent gravity g - a (its weight m (g - a)), g(q) from Pinocchio under it.
"""

import dataclasses
from pathlib import Path

from conftest import ALLEGRO, ALLEGRO_URDF
from cycle_inputs import joint_state
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import resolve_urdf
from grasp_torque_opt.core.resources import find_config
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.methods.dispatch import solve
import numpy as np
import pinocchio as pin
import pytest
from rclpy.qos import qos_profile_sensor_data
from ros_harness import Harness
from sensor_msgs.msg import Imu

G = np.array([9.81, 0.0, 0.0])  # the bundled scenario's gravity, palm down
MASS = load_scenario(find_config('allegro_right.yaml')).object.mass


def reference(apparent, q):
    """Give the command for the ball's weight under ``apparent`` gravity, solved here."""
    model = pin.buildModelFromUrdf(str(resolve_urdf(ALLEGRO_URDF, Path('.'))))
    model.gravity.linear = np.asarray(apparent, dtype=float)
    setup = GraspSetup.from_file(ALLEGRO)
    g = pin.computeGeneralizedGravity(model, model.createData(), q)[setup.hand.idx_v]
    wrench = np.concatenate((MASS * np.asarray(apparent, dtype=float), np.zeros(3)))
    ref = solve(dataclasses.replace(setup, external_wrench=wrench, torque_offset=g))
    assert ref.optimal
    return ref.tau + g


class ImuHarness(Harness):

    def __init__(self, **params):
        super().__init__(ALLEGRO, gravity_compensation=True, imu__enabled=True, **params)
        self.imu_pub = self.tester.create_publisher(Imu, 'imu', qos_profile_sensor_data)
        assert self.spin_until(lambda: self.imu_pub.get_subscription_count() > 0, 10.0)

    def send_imu(self, force, omega=(0.0, 0.0, 0.0), frame='palm_link'):
        msg = Imu()
        msg.header.frame_id = frame
        a, w = msg.linear_acceleration, msg.angular_velocity
        a.x, a.y, a.z = (float(v) for v in force)
        w.x, w.y, w.z = (float(v) for v in omega)
        self.imu_pub.publish(msg)

    def command_after_imu(self, setup, force, **kw):
        self.send_imu(force, **kw)
        self.spin_for(0.02)
        self.send_joint_state(*joint_state(setup))
        return self.next_command()


def test_an_imu_accelerating_the_hand_moves_the_load_by_m_a(allegro):
    h = ImuHarness(**{'imu.timeout_bounds': [0.5, 1.0]})
    try:
        for a in ([0.0, 9.81, 0.0], [-9.81, 0.0, 0.0], [0.0, 0.0, -4.0]):
            # The specific force an accelerometer reads: a - g.
            cmd = h.command_after_imu(allegro, np.array(a) - G)
            assert cmd is not None
            np.testing.assert_allclose(cmd, reference(G - np.array(a), allegro.q), atol=1e-7)
        # The hand accelerating along -x at 1 g (palm down, gravity +x): twice the weight.
        assert np.allclose(G - np.array([-9.81, 0, 0]), 2 * G)
    finally:
        h.close()


def last_diag(h, key):
    h.spin_until(lambda: bool(h.diagnostics) and key in h.diagnostics[-1], 2.0)
    return h.diagnostics[-1]


def test_a_bad_imu_is_rejected_and_the_scenarios_gravity_used(allegro):
    h = ImuHarness()
    try:
        nominal = reference(G, allegro.q)
        bad = [({'force': [float('nan'), 0.0, 0.0]}, 'imu.linear_acceleration'),
               ({'force': [-9.81, 0.0, 0.0], 'omega': [0.0, float('inf'), 0.0]},
                'imu.angular_velocity'),
               ({'force': [-900.0, 0.0, 0.0]}, 'exceeds imu.max_specific_force'),
               ({'force': [0.0, 0.0, 9.81], 'frame': 'world'}, "'world' is not the hand's base")]
        for n, (kw, why) in enumerate(bad, 1):
            cmd = h.command_after_imu(allegro, **kw)
            np.testing.assert_allclose(cmd, nominal, atol=1e-7)  # never from the bad one
            d = last_diag(h, 'rejected.imu')
            h.spin_until(lambda: int(h.diagnostics[-1].get('rejected.imu', 0)) >= n, 2.0)
            assert int(h.diagnostics[-1]['rejected.imu']) >= n
            assert why in h.diagnostics[-1]['last_rejection'], d
        # A good reading, then none: after imu.timeout_bounds' upper bound (no rate measured
        # from one reading) the scenario's gravity again, said in diagnostics.
        moved = h.command_after_imu(allegro, [-9.81, 9.81, 0.0])
        np.testing.assert_allclose(moved, reference([9.81, -9.81, 0.0], allegro.q), atol=1e-7)
        h.spin_for(0.1)
        h.send_joint_state(*joint_state(allegro))
        np.testing.assert_allclose(h.next_command(), nominal, atol=1e-7)
        h.spin_until(lambda: 'stale' in h.diagnostics[-1].get('imu', ''), 2.0)
        assert 'imu stale' in h.diagnostics[-1]['imu']
        assert h.diagnostics[-1]['_level'] == 1  # WARN
    finally:
        h.close()


@pytest.mark.parametrize('lie', ['1.9 g sideways', 'rate chatter'])
def test_an_imu_lie_is_refused_and_every_joint_state_gets_the_nominal_command(allegro, lie):
    # Issue 33: a still hand told 1.9 g sideways (every command pulled at the true grasp),
    # or +-29 rad/s alternating (every other grasp infeasible: commands lost). The upper
    # freshness bound long: the rate rule compares no two readings further apart than it
    # (a reading after such a pause may be true), and a loaded machine once paused 50 ms
    # (the default) between two of these readings, waiting for a command.
    h = ImuHarness(**{'imu.timeout_bounds': [0.005, 5.0]})
    try:
        nominal = reference(G, allegro.q)
        # Each reading taken before the next is sent, as a node spinning at 1 kHz takes
        # them (sensor-data QoS keeps the last 5 of a burst).
        for _ in range(5):  # a still IMU first: the reading before the lie is a true one
            h.send_imu(-G)
            h.spin_for(0.001)
        for k in range(20):
            for j in range(5):
                if lie == 'rate chatter':
                    h.send_imu(-G, omega=(0.0, 29.0 if (5 * k + j) % 2 else -29.0, 0.0))
                else:
                    h.send_imu([0.0, 0.0, -18.64])
                h.spin_for(0.001)
            h.send_joint_state(*joint_state(allegro))
            cmd = h.next_command()
            assert cmd is not None, k
            np.testing.assert_allclose(cmd, nominal, atol=1e-7)
        why = 'imu.max_arm_acceleration' if lie == '1.9 g sideways' else \
            'imu.max_angular_acceleration'
        assert why in h.node.controller.last_rejection
        d = last_diag(h, 'imu.refused')
        assert why in h.diagnostics[-1]['imu.refused'], d
    finally:
        h.close()


def test_a_driver_without_efforts_turns_the_estimation_off_once(allegro):
    h = ImuHarness(**{'effort_estimation.enabled': True})
    try:
        for _ in range(3):  # the harness's joint states carry NaN efforts
            h.send_joint_state(*joint_state(allegro))
            assert h.next_command() is not None
        h.spin_until(lambda: any('effort_estimation off' in m.msg for m in h.logs), 2.0)
        h.spin_for(0.2)
        said = [m for m in h.logs if 'effort_estimation off' in m.msg]
        assert len(said) == 1 and 'is not finite' in said[0].msg
        h.spin_until(lambda: bool(h.diagnostics) and 'effort_estimation' in h.diagnostics[-1], 2.0)
        assert h.diagnostics[-1]['effort_estimation'].startswith('effort_estimation off')
    finally:
        h.close()


def test_the_subscriptions_are_made_from_the_inputs_table():
    """Every input of the registry has its message class and conversion on the ROS side."""
    from grasp_torque_opt.control.inputs.registry import REGISTRY
    from grasp_torque_opt.ros.node.inputs import MESSAGES

    assert set(MESSAGES) == set(REGISTRY)
    for name, (msg_type, _) in MESSAGES.items():
        package, _, kind = REGISTRY[name].message.partition('/msg/')
        assert (msg_type.__module__.split('.')[0], msg_type.__name__) == (package, kind), name
