# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The rate rule's steps: on the segment between two commands, their wrenches in the cone.

A step cut joint by joint (each joint clipped to the rate on its own) is no combination
of the two commands: its contact wrenches are nobody's. Cut along the segment, the step
is the same combination of two commands whose wrenches are certified, so its wrenches
are that combination of theirs: inside the exact cone, never pulling.
"""

from cycle_inputs import base_poses, fresh, joint_state, tilted
from grasp_torque_opt.control.inputs.contacts import ContactsReading
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.rates import slewed, step_wrenches
from grasp_torque_opt.core.friction import cone_margin
import numpy as np


def test_a_step_is_on_the_segment_and_no_joint_moves_faster():
    in_force = np.array([0.1, -0.2, 0.3])
    target = np.array([0.5, -0.2, -0.1])
    cmd, s = slewed(in_force, target, 0.1, np.full(3, 1.0))
    np.testing.assert_allclose(cmd, in_force + s * (target - in_force), atol=1e-15)
    assert np.abs(cmd - in_force).max() <= 0.1 + 1e-15
    assert s == 0.1 / 0.4
    assert slewed(in_force, target, 0.4, np.full(3, 1.0)) is None  # within the step: whole
    assert slewed(in_force, target, 0.1, np.full(3, 0.2)) is None  # in force over a limit


def test_step_wrenches_combine_both_ends_and_zero_torques_have_none():
    a, b = np.ones((2, 4)), 3.0 * np.ones((2, 4))
    np.testing.assert_allclose(step_wrenches(a, b, 0.25), 1.5 * np.ones((2, 4)))
    np.testing.assert_allclose(step_wrenches(np.zeros((0, 4)), b, 0.25), 0.75 * np.ones((2, 4)))
    assert step_wrenches(None, b, 0.5) is None
    assert step_wrenches(np.ones((3, 4)), b, 0.5) is None  # another contact set


def test_slewed_commands_keep_their_wrenches_in_the_exact_cone(allegro):
    rate = 0.2  # N m/s: a 1 ms cycle moves a joint 0.2 mN m
    ctrl = fresh(allegro, max_torque_rate=rate)
    names, pos = joint_state(allegro)
    points, quat = base_poses(allegro)
    friction = allegro.friction
    ends = []
    for q in (quat, tilted(quat, 0.1)):  # the two grasps, each from a controller of its own
        own = fresh(allegro)
        own.take('joint_states', JointStateReading(names, pos), 0.0)
        own.take('contacts', ContactsReading('', points, q), 0.0)
        ends.append(own.cycle(0.0).command)
    ctrl.take('joint_states', JointStateReading(names, pos), 0.0)
    ctrl.take('contacts', ContactsReading('', points, quat), 0.0)
    prev = ctrl.cycle(0.0).command
    np.testing.assert_allclose(prev, ends[0], atol=1e-7)
    ctrl.take('contacts', ContactsReading('', points, tilted(quat, 0.1)), 0.0)
    steps = 0
    for k in range(1, 400):
        now = 1e-3 * k
        ctrl.take('joint_states', JointStateReading(names, pos), now)
        result = ctrl.cycle(now)
        cmd = result.command
        if result.wrenches is None:  # reached: the certified command whole
            np.testing.assert_allclose(cmd, ends[1], atol=1e-7)
            break
        steps += 1
        delta, want = cmd - prev, ends[1] - prev
        assert np.abs(delta).max() <= rate * 1e-3 + 1e-12
        # On the segment towards the certified command: parallel to what is left.
        s = float(delta @ want / (want @ want))
        np.testing.assert_allclose(delta, s * want, atol=1e-7)  # the solver's tolerance
        assert cone_margin(result.wrenches, friction.mu1, friction.mu2).min() >= -1e-9
        prev = cmd
    else:
        raise AssertionError('the certified command was never reached')
    full = float(np.abs(ends[1] - ends[0]).max())
    assert steps >= int(full / (rate * 1e-3)) - 1 and steps > 5
    assert ctrl.counters.slew_limited == steps and ctrl.counters.slew_refused == 0
