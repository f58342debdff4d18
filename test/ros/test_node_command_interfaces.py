# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The node's command interfaces on real topics: each message's type, length and units.

The Allegro's node in each ``command_interface``, its certified torques beside it on
``~/effort_commands_stamped``: the message on the interface's own topic must be those
torques in the driver's units, written again here from the formulas of docs/node.md
(q_hold + tau / K [rad], tau / (k_t gear) [A], the hybrid JointState's fields), and
nothing on effort_commands. Bad constants stop the node at start, naming the parameter.
"""

from conftest import ALLEGRO
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.ros.node import COMMAND_QOS, GraspTorqueNode
import numpy as np
import pytest
import rclpy
from rclpy.parameter import Parameter
from ros_harness import DOMAIN, Harness
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray

SETUP = GraspSetup.from_file(ALLEGRO)
CONSTANTS = {
    'effort': {},
    'position': {'position__stiffness': [0.8]},
    'current': {'current__torque_constant': [0.35], 'current__gear_ratio': [2.0],
                'current__limit': [2.0]},
    'hybrid': {'hybrid__kp': [1.5], 'hybrid__kd': [0.01]},
}
TOPICS = {'effort': 'effort_commands', 'position': 'position_commands',
          'current': 'current_commands', 'hybrid': 'hybrid_commands'}


def joint_state():
    hand = SETUP.hand
    names = hand.one_dof_joints(hand.model)
    return names, [float(SETUP.q[hand.model.joints[hand.model.getJointId(n)].idx_q])
                   for n in names]


@pytest.mark.parametrize('name', sorted(CONSTANTS))
def test_each_interface_publishes_the_certified_torque_in_its_units(name):
    h = Harness(ALLEGRO, command_interface=name, publish_stamped_command=True,
                joint_state_timeout=5.0, **CONSTANTS[name])
    try:
        got, stamped, efforts = [], [], []
        t = h.tester
        kind = JointState if name == 'hybrid' else Float64MultiArray
        t.create_subscription(kind, TOPICS[name], got.append, COMMAND_QOS)
        t.create_subscription(JointState, 'grasp_torque_node/effort_commands_stamped',
                              stamped.append, COMMAND_QOS)
        if name != 'effort':
            t.create_subscription(Float64MultiArray, 'effort_commands', efforts.append,
                                  COMMAND_QOS)
        names, positions = joint_state()
        for _ in range(3):
            h.send_joint_state(names, positions)
            h.spin_until(lambda: got and stamped, 2.0)
        assert got and stamped, 'no command'
        hand = SETUP.hand
        m, joints = hand.m, list(hand.joints)
        tau = np.array(stamped[-1].effort)  # the certified torques [N m]
        assert list(stamped[-1].name) == joints and tau.shape == (m,)
        assert np.all(np.abs(tau) <= hand.torque_limits) and np.any(tau != 0)
        q = np.array([positions[names.index(j)] for j in joints])  # q_hold: this state's
        msg = got[-1]
        if name == 'hybrid':
            assert list(msg.name) == joints
            assert msg.header.frame_id == hand.base_frame
            np.testing.assert_allclose(msg.position, q, atol=1e-12)  # [rad]
            np.testing.assert_array_equal(msg.velocity, np.zeros(m))  # [rad/s]
            np.testing.assert_array_equal(msg.effort, tau)  # [N m]
        else:
            values = np.array(msg.data)
            assert values.shape == (m,) and np.all(np.isfinite(values))
            expected = {'effort': tau, 'position': q + tau / 0.8,  # [N m], [rad]
                        'current': tau / (0.35 * 2.0)}[name]  # [A]
            np.testing.assert_allclose(values, expected, rtol=1e-12, atol=1e-12)
        assert efforts == [], 'an effort command beside another interface'
        assert h.node.count_publishers('effort_commands') == (1 if name == 'effort' else 0)
    finally:
        h.close()


def start(**params):
    """Start the Allegro's plain node in a context of its own; raise what its start raises."""
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=DOMAIN)
    overrides = [Parameter('scenario', value=str(ALLEGRO))]
    overrides += [Parameter(k.replace('__', '.'), value=v) for k, v in params.items()]
    try:
        GraspTorqueNode(context=context, parameter_overrides=overrides).destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


@pytest.mark.parametrize('params, match', [
    ({'command_interface': 'position'},
     r'^position.stiffness: must be set for command_interface position'),
    ({'command_interface': 'current', 'current__torque_constant': [0.35]},
     r'^current.limit: must be set for command_interface current'),
    ({'command_interface': 'hybrid', 'hybrid__kp': [1.0]},
     r'^hybrid.kd: must be set for command_interface hybrid'),
    ({'command_interface': 'position', 'position__stiffness': [1.0, 2.0]},
     r'^position.stiffness: must have 1 entry \(every joint\) or 16'),
    ({'command_interface': 'position', 'position__stiffness': [-1.0]},
     r'^position.stiffness: every entry must be > 0'),
    ({'command_interface': 'current', 'current__torque_constant': [0.35],
      'current__limit': [0.0]}, r'^current.limit: every entry must be > 0'),
    ({'command_interface': 'hybrid', 'hybrid__kp': [1.0], 'hybrid__kd': [-0.1]},
     r'^hybrid.kd: every entry must be >= 0'),
])
def test_bad_constants_stop_the_node_naming_the_parameter(params, match):
    with pytest.raises(InputError, match=match):
        start(**params)


def test_an_unknown_interface_is_refused_with_the_choices():
    with pytest.raises(InputError, match=r'^command_interface: must be one of effort, '
                       r'position, current, hybrid$'):
        start(command_interface='torque')
