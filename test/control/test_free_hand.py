# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
No object in the hand (``hold_object`` false): the command is g(q) alone.

The switch both ways goes through the rate rule with every step's contact wrenches in
the cone.

g(q) is checked against Pinocchio on a model built here from the URDF (not the node's).
"""

import dataclasses

from conftest import ALLEGRO_URDF, CONFIG
from cycle_inputs import fresh, joint_state
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.core.friction import cone_margin
from grasp_torque_opt.core.hand import resolve_urdf
import numpy as np
import pinocchio as pin

GRAVITY = (9.81, 0.0, 0.0)  # the Allegro scenario's: palm down


def own_gravity_torque(setup, q, gravity=GRAVITY):
    """g(q) of the actuated joints from a Pinocchio model of the URDF, built here."""
    model = pin.buildModelFromUrdf(str(resolve_urdf(ALLEGRO_URDF, CONFIG)))
    model.gravity.linear = np.asarray(gravity)
    g = pin.computeGeneralizedGravity(model, model.createData(), q)
    return np.array([g[model.joints[model.getJointId(j)].idx_v] for j in setup.hand.joints])


def test_no_object_commands_the_fingers_own_gravity_torques(allegro):
    ctrl = fresh(allegro, gravity_compensation=True, gravity=GRAVITY, hold_object=False)
    rng = np.random.default_rng(0)
    for k in range(3):
        model = allegro.hand.model  # anywhere within the joints' limits: the hand is free
        q = rng.uniform(model.lowerPositionLimit, model.upperPositionLimit) if k else allegro.q
        names, pos = joint_state(allegro, q)
        ctrl.take('joint_states', JointStateReading(names, pos), 1e-3 * k)
        result = ctrl.cycle(1e-3 * k)
        assert result.kind == 'solution', result.fault
        np.testing.assert_allclose(result.command, own_gravity_torque(allegro, q), atol=1e-9)
        assert result.solution.wrenches.shape == (0, 4) and result.maps is None
    assert np.abs(result.command).max() > 1e-3  # the fingers do weigh something


def test_no_object_without_gravity_compensation_commands_zeros(allegro):
    ctrl = fresh(allegro, gravity_compensation=False, hold_object=False)
    names, pos = joint_state(allegro)
    ctrl.take('joint_states', JointStateReading(names, pos), 0.0)
    result = ctrl.cycle(0.0)
    assert result.kind == 'solution' and not np.any(result.command)


def test_g_over_a_torque_limit_is_no_command(allegro):
    weak = dataclasses.replace(allegro, hand=dataclasses.replace(
        allegro.hand, torque_limits=np.full(allegro.hand.m, 1e-4)))
    ctrl = fresh(weak, gravity_compensation=True, gravity=GRAVITY, hold_object=False)
    names, pos = joint_state(allegro)
    ctrl.take('joint_states', JointStateReading(names, pos), 0.0)
    result = ctrl.cycle(0.0)
    assert result.command is None and 'over the limit' in result.fault


def test_letting_go_and_grasping_again_ride_the_rate_rule(allegro):
    rate, dt = 2.0, 1e-3
    ctrl = fresh(allegro, gravity_compensation=True, gravity=GRAVITY, max_torque_rate=rate,
                 command_period=dt)
    names, pos = joint_state(allegro)
    g = own_gravity_torque(allegro, allegro.q)
    ctrl.take('joint_states', JointStateReading(names, pos), 0.0)
    grasp = ctrl.cycle(0.0).command
    friction = allegro.friction
    now, prev = 0.0, grasp
    for hold, end in ((False, g), (True, grasp)):
        ctrl.config = dataclasses.replace(ctrl.config, hold_object=hold)
        steps = 0
        for _ in range(2000):
            now += dt
            ctrl.take('joint_states', JointStateReading(names, pos), now)
            result = ctrl.cycle(now)
            assert result.kind == 'solution', result.fault
            assert np.abs(result.command - prev).max() <= rate * dt + 1e-12  # never a jump
            prev = result.command
            if result.wrenches is None:  # reached: the end whole
                break
            steps += 1
            faded = np.zeros((0, 4)) if result.faded is None else result.faded[1]
            every = np.vstack((result.wrenches, faded))
            assert cone_margin(every, friction.mu1, friction.mu2).min() >= -1e-6
        else:
            raise AssertionError('the end was never reached')
        np.testing.assert_allclose(prev, end, atol=1e-6)
        assert steps >= int(np.abs(end - grasp if hold else g - grasp).max() / (rate * dt)) - 1
    assert ctrl.counters.slew_refused == 0


def test_a_quiet_contacts_topic_stops_the_grasp_but_not_the_free_hand(allegro):
    from cycle_inputs import base_poses
    from grasp_torque_opt.control.inputs.contacts import ContactsReading

    ctrl = fresh(allegro, gravity_compensation=True, gravity=GRAVITY, contacts_timeout=0.05)
    names, pos = joint_state(allegro)
    ctrl.take('contacts', ContactsReading('', *base_poses(allegro)), 0.0)
    ctrl.take('joint_states', JointStateReading(names, pos), 0.2)  # contacts 0.2 s old
    assert ctrl.cycle(0.2).kind != 'solution'
    ctrl.config = dataclasses.replace(ctrl.config, hold_object=False)
    ctrl.take('joint_states', JointStateReading(names, pos), 0.201)
    assert ctrl.cycle(0.201).kind == 'solution'
