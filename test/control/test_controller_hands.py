# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The control cycle on a coupled hand and on a hand inside a robot."""

from conftest import ALLEGRO, CONFIG, scenario_doc, setup_from_doc
from cycle_inputs import fresh, joint_state
from g1_grasp import ARM_Q, g1_doc, HAND_Q
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.methods.dispatch import solve
import numpy as np
import pinocchio as pin
import pytest

PAIRS = [('joint_3.0', 'joint_2.0'), ('joint_7.0', 'joint_6.0'), ('joint_11.0', 'joint_10.0')]


@pytest.fixture(scope='module')
def coupled():
    doc = scenario_doc(ALLEGRO)
    q = doc['grasp']['joint_positions']
    doc['hand']['joints'] = [j for j in doc['hand']['joints'] if j not in dict(PAIRS)]
    doc['hand']['coupling'] = {f: {'follows': t, 'multiplier': q[f] / q[t], 'offset': 0.01}
                               for f, t in PAIRS}
    for f, t in PAIRS:
        q[t] = (q[f] - 0.01) / (q[f] / q[t])
        del q[f]
    return setup_from_doc(doc, CONFIG)


def test_a_coupled_hand_is_commanded_by_actuator_from_either_joint_state(coupled):
    ref = solve(coupled)
    assert ref.optimal and ref.tau.shape == (13,)
    actuators_only = fresh(coupled)
    actuators_only.take('joint_states',
                        JointStateReading(*joint_state(coupled, names=coupled.hand.joints)), 0.0)
    a = actuators_only.cycle(0.0)
    assert a.kind == 'solution'
    np.testing.assert_allclose(a.command, ref.tau, atol=1e-9)
    # All joints, the followers measured off their coupling: the coupling decides.
    names, positions = joint_state(coupled)
    positions = [p + 0.05 if n in dict(PAIRS) else p for n, p in zip(names, positions)]
    every_joint = fresh(coupled)
    every_joint.take('joint_states', JointStateReading(names, positions), 0.0)
    np.testing.assert_allclose(every_joint.cycle(0.0).command, ref.tau, atol=1e-9)


def test_gravity_compensation_of_a_coupled_hand_is_c_transpose_g(coupled):
    gravity = np.array([9.81, 0.0, 0.0])
    ctrl = fresh(coupled, gravity_compensation=True, gravity=tuple(gravity))
    ctrl.take('joint_states', JointStateReading(*joint_state(coupled, names=coupled.hand.joints)),
              0.0)
    r = ctrl.cycle(0.0)
    assert r.kind == 'solution'
    model = coupled.hand.model
    model.gravity.linear = gravity
    g = pin.computeGeneralizedGravity(model, model.createData(), coupled.q)
    iv = {n: model.joints[model.getJointId(n)].idx_v for n in model.names[1:]}
    expected = g[[iv[n] for n in coupled.hand.joints]]
    for f, t in PAIRS:  # a follower's gravity torque, carried by its actuator times k
        k = coupled.hand.coupling.followers[f].multiplier
        expected[coupled.hand.joints.index(t)] += k * g[iv[f]]
    np.testing.assert_allclose(r.gravity_torque, expected, atol=1e-12)
    np.testing.assert_allclose(r.command, r.solution.tau + expected, atol=1e-12)


def test_a_hand_in_a_robot_follows_the_robots_joint_states_in_the_palm_frame():
    setup = setup_from_doc(g1_doc(), CONFIG)
    ref = solve(setup)
    ctrl = fresh(setup, gravity_compensation=True, gravity=(0.0, 0.0, -9.81))
    names = list(ARM_Q) + list(HAND_Q)
    still = fresh(setup, gravity_compensation=True, gravity=(0.0, 0.0, -9.81))
    still.take('joint_states', JointStateReading(list(HAND_Q), list(HAND_Q.values())), 0.0)
    ctrl.take('joint_states',
              JointStateReading(names, list(ARM_Q.values()) + list(HAND_Q.values())), 0.0)
    a, b = still.cycle(0.0), ctrl.cycle(0.0)
    assert a.kind == b.kind == 'solution'
    # Gravity is given in the palm's axes: its torques do not move with the arm either.
    np.testing.assert_allclose(b.command, a.command, atol=1e-9)
    np.testing.assert_allclose(a.solution.tau, ref.tau, atol=1e-9)
