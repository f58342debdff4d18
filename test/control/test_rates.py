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

import dataclasses
from pathlib import Path

from campaign import TrueGrasp
from conftest import ALLEGRO_URDF
from cycle_inputs import base_poses, fresh, joint_state, tilted
from grasp_torque_opt.control.inputs.contacts import ContactsReading
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.rates import slewed, step_wrenches, within_step
from grasp_torque_opt.core.friction import cone_margin
from grasp_torque_opt.core.hand import resolve_urdf
import numpy as np
import pinocchio as pin


def test_a_step_is_on_the_segment_and_no_joint_moves_faster():
    in_force = np.array([0.1, -0.2, 0.3])
    target = np.array([0.5, -0.2, -0.1])
    cmd, s = slewed(in_force, target, 0.1, np.full(3, 1.0))
    np.testing.assert_allclose(cmd, in_force + s * (target - in_force), atol=1e-15)
    assert np.abs(cmd - in_force).max() <= 0.1 + 1e-15
    assert s == 0.1 / 0.4
    assert slewed(in_force, target, 0.4, np.full(3, 1.0)) is None  # within the step: whole
    assert slewed(in_force, target, 0.1, np.full(3, 0.2)) is None  # in force over a limit


def test_within_a_step_no_step_is_made_with_or_without_a_shift():
    # The controller's shortcut: within_step(in_force, target, step) means slewed gives
    # None (the certified command whole), whatever the shift of g(q); the converse
    # holds without a shift. Checked on random commands around the step's size.
    rng = np.random.default_rng(3)
    limits = np.full(6, 1.0)
    seen = {True: 0, False: 0}
    for _ in range(2000):
        in_force = rng.uniform(-0.9, 0.9, 6)
        step = rng.uniform(0.0, 0.05)
        target = in_force + rng.uniform(-1.0, 1.0, 6) * rng.choice([0.5, 1.0, 2.0]) * step
        shift = rng.uniform(-1.0, 1.0, 6) * step
        within = within_step(in_force, target, step)
        seen[within] += 1
        if within:
            assert slewed(in_force, target, step, limits) is None
            assert slewed(in_force, target, step, limits, shift) is None
        else:
            assert slewed(in_force, target, step, limits) is not None
    assert min(seen.values()) > 200  # both sides drawn
    assert not within_step(in_force, np.full(6, np.nan), 1.0)
    assert not within_step(in_force, np.zeros(5), 1.0)


def test_step_wrenches_combine_both_ends_and_zero_torques_have_none():
    a, b = np.ones((2, 4)), 2 * np.ones((2, 4))
    ab = ('a', 'b')
    w, gone, faded = step_wrenches(a, ab, b, ab, 0.25)
    np.testing.assert_allclose(w, 1.25 * np.ones((2, 4)))
    assert gone == () and faded.shape == (0, 4)
    np.testing.assert_allclose(step_wrenches(np.zeros((0, 4)), (), b, ab, 0.25)[0],
                               0.5 * np.ones((2, 4)))
    assert step_wrenches(None, None, b, ab, 0.5) is None
    assert step_wrenches(a, ('a', 'a'), b, ab, 0.5) is None  # a link named twice


def test_across_a_set_change_a_contact_fades_out_and_another_in():
    old = np.array([[1.0, 0, 2, 0], [0, 1.0, 3, 0]])
    new = np.array([[0, 0, 4.0, 0], [0, 0, 5.0, 0]])
    w, gone, faded = step_wrenches(old, ('a', 'b'), new, ('b', 'c'), 0.25)
    np.testing.assert_allclose(w, [0.75 * old[1] + 0.25 * new[0], 0.25 * new[1]])
    assert gone == ('a',)
    np.testing.assert_allclose(faded, [0.75 * old[0]])


def test_slewed_commands_keep_their_wrenches_in_the_exact_cone(allegro):
    rate = 1.0  # N m/s: a 0.1 ms cycle moves a joint 0.1 mN m
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
        now = 1e-4 * k
        ctrl.take('joint_states', JointStateReading(names, pos), now)
        result = ctrl.cycle(now)
        cmd = result.command
        if result.wrenches is None:  # reached: the certified command whole
            np.testing.assert_allclose(cmd, ends[1], atol=1e-7)
            break
        steps += 1
        delta, want = cmd - prev, ends[1] - prev
        assert np.abs(delta).max() <= rate * 1e-4 + 1e-12
        # On the segment towards the certified command: parallel to what is left.
        s = float(delta @ want / (want @ want))
        np.testing.assert_allclose(delta, s * want, atol=1e-7)  # the solver's tolerance
        assert cone_margin(result.wrenches, friction.mu1, friction.mu2).min() >= -1e-9
        prev = cmd
    else:
        raise AssertionError('the certified command was never reached')
    full = float(np.abs(ends[1] - ends[0]).max())
    assert steps >= int(full / (rate * 1e-4)) - 1 and steps > 5
    assert ctrl.counters.slew_limited == steps and ctrl.counters.slew_refused == 0


LIFT = 1  # the middle finger lifts off: three contacts left


def lifted(setup):
    """Give the grasp's joint positions with the lifted finger's proximal flexion opened."""
    model, q = setup.hand.model, setup.q.copy()
    q[model.joints[model.getJointId('joint_5.0')].idx_q] -= 0.1
    return q


def union_torque(setup, q, links, wrenches):
    """J^T w summed over contacts given by link (each from the grasp's own contact there)."""
    by_link = {c.link: c for c in setup.contacts}
    maps = dataclasses.replace(setup, q=q, contacts=[by_link[k] for k in links]).maps()
    return maps.J.T @ np.asarray(wrenches).reshape(-1)


def test_a_contact_set_change_and_flapping_go_through_the_rate_rule(allegro):
    # Issue 33, item 4a: a change of the contact set was published whole (a jump), and a
    # set flapping at 1 kHz made every command a step of the whole difference.
    rate, dt = 1.0, 1e-3
    ctrl = fresh(allegro, max_torque_rate=rate)
    q = lifted(allegro)
    links = [c.link for c in allegro.contacts]
    three = links[:LIFT] + links[LIFT + 1:]
    names, pos = joint_state(allegro, q)
    points, quat = base_poses(allegro, q)
    keep = [i for i in range(4) if i != LIFT]
    sets = {4: (';' + ','.join(links), points, quat),
            3: (';' + ','.join(three), points[keep], quat[keep])}
    ctrl.take('contacts', ContactsReading(*sets[4]), 0.0)
    ctrl.take('joint_states', JointStateReading(names, pos), 0.0)
    prev = ctrl.cycle(0.0).command
    friction, steps = allegro.friction, 0
    for k in range(1, 300):
        now = dt * k
        # Three contacts from now on, then the set flapping every cycle from k = 200.
        ctrl.take('contacts', ContactsReading(*sets[3 if k < 200 or k % 2 else 4]), now)
        ctrl.take('joint_states', JointStateReading(names, pos), now)
        result = ctrl.cycle(now)
        assert result.kind == 'solution'
        cmd = result.command
        assert np.abs(cmd - prev).max() <= rate * dt + 1e-12  # never a jump
        if result.wrenches is not None:  # a step: its wrenches, fading ones too, hold
            steps += 1
            gone, faded = result.faded
            every = np.vstack((result.wrenches, faded))
            assert cone_margin(every, friction.mu1, friction.mu2).min() >= -1e-6
            # They are the step's: J^T w over both sets' contacts gives its torque.
            np.testing.assert_allclose(
                union_torque(allegro, q, list(result.maps.links) + list(gone), every), cmd,
                atol=1e-6)
        prev = cmd
    assert steps > 10 and ctrl.counters.slew_refused == 0


def test_a_step_is_at_most_the_rate_times_the_nominal_period_whatever_the_gap(allegro):
    # Issue 33, item 4b: the rule allowed rate x gap (a loop slowed to 76 Hz took steps
    # of 0.55-0.69 N m).
    rate, period = 1.0, 1e-3
    ctrl = fresh(allegro, max_torque_rate=rate, command_period=period)
    names, pos = joint_state(allegro)
    points, quat = base_poses(allegro)
    ctrl.take('joint_states', JointStateReading(names, pos), 0.0)
    ctrl.take('contacts', ContactsReading('', points, quat), 0.0)
    first = ctrl.cycle(0.0).command
    gap = 0.04  # within joint_state_timeout
    ctrl.take('contacts', ContactsReading('', points, tilted(quat, 0.1)), gap)
    ctrl.take('joint_states', JointStateReading(names, pos), gap)
    result = ctrl.cycle(gap)
    assert result.wrenches is not None  # a step, not the certified command whole
    assert np.abs(result.command - first).max() <= rate * period + 1e-12


def test_a_recovery_from_zeros_steps_the_contact_wrenches_with_gravity_whole(allegro):
    # Issue 33, item 4c: with gravity compensation a recovery step was s (tau + g): the
    # fingers' wrenches s W - (1 - s) J^-T g, 15 of 15 outside the cone.
    gravity = np.array([9.81, 0.0, 0.0])
    ctrl = fresh(allegro, max_torque_rate=1.0, gravity_compensation=True,
                 gravity=tuple(gravity), fault_policy='zero', hold_time=0.01,
                 joint_state_timeout=0.05)
    names, pos = joint_state(allegro)
    model = allegro.hand.model.copy()
    model.gravity.linear = gravity
    g = pin.computeGeneralizedGravity(model, model.createData(), allegro.q)[allegro.hand.idx_v]
    maps = allegro.maps()
    ctrl.take('joint_states', JointStateReading(names, pos), 0.0)
    assert ctrl.cycle(0.0).kind == 'solution'
    assert ctrl.watchdog(0.2).kind == 'zero'  # stale: zero torques in force
    friction, steps, now = allegro.friction, 0, 0.2
    while True:
        now += 1e-3
        ctrl.take('joint_states', JointStateReading(names, pos), now)
        result = ctrl.cycle(now)
        assert result.kind == 'solution'
        # What the fingers exert on the ball under the true gravity, from Pinocchio.
        exerted = np.linalg.solve(maps.J.T, result.command - g).reshape(-1, 4)
        certified = result.solution.wrenches
        s = float(exerted[:, 2].sum() / certified[:, 2].sum())
        np.testing.assert_allclose(exerted, s * certified, atol=1e-6)
        assert cone_margin(exerted, friction.mu1, friction.mu2).min() >= -1e-6
        if result.wrenches is None:
            break
        steps += 1
        assert 0.0 < s < 1.0
    assert steps >= 3


def test_a_step_takes_the_gravity_torque_of_the_joint_state_it_answers(allegro):
    # Issue 33's campaign (part 3): a finger leaving and touching at 1 kHz, with gravity
    # compensation. A step blended the whole commands, so it carried (1 - s) of the
    # gravity torque of the joint state before, (1 - s)(g(q_before) - g(q)): at q the
    # finger fading in pushed with that on top of s times its certified wrench (the
    # middle finger lifted by 0.1 rad and back: 100 of 200 commands outside the exact
    # cone at q before the fix). Each command is judged at the joint state it answers,
    # apart from the package's maps (campaign.TrueGrasp): there the lifted finger is
    # free, the others hold the ball.
    gravity = (9.81, 0.0, 0.0)
    ctrl = fresh(allegro, max_torque_rate=20.0, gravity_compensation=True, gravity=gravity)
    urdf = resolve_urdf(ALLEGRO_URDF, Path('.'))
    q_lift = lifted(allegro)
    links = [c.link for c in allegro.contacts]
    keep = [i for i in range(4) if i != LIFT]
    states = []
    for q, idx in ((q_lift, keep), (allegro.q, list(range(4)))):  # lifted first
        points, quat = base_poses(allegro, q)
        reading = ContactsReading(';' + ','.join(links[i] for i in idx), points[idx], quat[idx])
        truth = TrueGrasp(dataclasses.replace(allegro, q=q), urdf, gravity,
                          contacts=[allegro.contacts[i] for i in idx])
        states.append((JointStateReading(*joint_state(allegro, q)), reading, truth))
    verdicts, steps = [], 0
    for k in range(200):
        js, reading, truth = states[k % 2]
        ctrl.take('contacts', reading, 1e-3 * k)
        ctrl.take('joint_states', js, 1e-3 * k)
        result = ctrl.cycle(1e-3 * k)
        assert result.kind == 'solution'
        steps += result.wrenches is not None
        verdicts.append(truth.verdict(result.command, True))
    assert steps > 100 and ctrl.counters.slew_refused == 0
    assert set(verdicts) <= {'ok', 'weak'}, {v: verdicts.count(v) for v in set(verdicts)}
