# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Every method on coupled hands, against joint torques with the coupling as constraints."""

import copy
import dataclasses
import json

from conftest import CONFIG, setup_from_doc
from coupled_reference import coupled_lp, coupled_qp, mechanism
from grasp_torque_opt.methods.capacity import load_capacity
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.methods.engines import score_batch
from grasp_torque_opt.methods.explain import explain
from grasp_torque_opt.methods.score import ScoreJob
from independent import assert_holds
import numpy as np
import pytest
import yaml

#: Allegro fingers with the distal joint coupled to the middle one, as in many hands.
ALLEGRO_COUPLED = [('joint_3.0', 'joint_2.0'), ('joint_7.0', 'joint_6.0'),
                   ('joint_11.0', 'joint_10.0')]
PLANAR_COUPLED = [('joint2', 'joint1'), ('joint4', 'joint3')]


def coupled(doc, pairs, limit=None):
    """
    Return (coupled setup, uncoupled setup, S, A) of a scenario with ``pairs`` coupled.

    Each follower follows its target with the ratio of their positions in the scenario
    (no offset), so the scenario's pose satisfies the coupling.
    """
    doc = copy.deepcopy(doc)
    q = doc['grasp']['joint_positions']
    all_joints = list(doc['hand']['joints'])
    limits = doc['hand']['torque_limits']
    limits = limits if isinstance(limits, list) else [limits] * len(all_joints)
    followers = dict(pairs)
    actuators = [j for j in all_joints if j not in followers]
    uncoupled = setup_from_doc(doc)
    doc['hand']['joints'] = actuators
    doc['hand']['torque_limits'] = [lim for j, lim in zip(all_joints, limits)
                                    if j not in followers]
    doc['hand']['coupling'] = {f: {'follows': t, 'multiplier': q[f] / q[t]} for f, t in pairs}
    for f in followers:
        del q[f]
    setup = setup_from_doc(doc)
    S, A = mechanism(all_joints, actuators, [(f, t, q_f_over(uncoupled, f, t))
                                             for f, t in pairs])
    return setup, uncoupled, S, A


def q_f_over(setup, f, t):
    """Return the ratio of the positions of joints ``f`` and ``t`` in the setup."""
    model = setup.hand.model
    iq = [model.joints[model.getJointId(n)].idx_q for n in (f, t)]
    return setup.q[iq[0]] / setup.q[iq[1]]


@pytest.fixture(scope='module', params=['planar', 'allegro'])
def hand(request, planar_doc, allegro_doc):
    if request.param == 'planar':
        return coupled(planar_doc, PLANAR_COUPLED)
    return coupled(allegro_doc, ALLEGRO_COUPLED)


def test_the_coupled_hand_has_one_torque_per_actuator(hand):
    setup, uncoupled, S, _ = hand
    assert setup.hand.m == S.shape[1] < uncoupled.hand.m
    np.testing.assert_allclose(setup.q, uncoupled.q, atol=1e-12)
    # J C: the coupled Jacobian is the uncoupled one times the velocity map.
    C = setup.hand.velocity_map
    J_full = uncoupled.maps().J
    cols = [uncoupled.hand.joints.index(n) for n in setup.hand.model.names[1:]
            if n in uncoupled.hand.joints]
    assert setup.maps().J.shape == (J_full.shape[0], setup.hand.m)
    idx = [setup.hand.model.joints[setup.hand.model.getJointId(n)].idx_v
           for n in uncoupled.hand.joints]
    np.testing.assert_allclose(setup.maps().J, J_full @ C[idx], atol=1e-12)
    assert len(cols) == uncoupled.hand.m


def test_the_tau_qp_equals_the_coupled_joint_torque_qp(hand):
    setup, uncoupled, S, A = hand
    sol = solve(setup)
    assert sol.optimal, sol.message
    maps = setup.maps()
    assert_holds(setup, maps, sol.tau, sol.wrenches)
    u = coupled_qp(uncoupled, uncoupled.maps(), S, A, setup.hand.torque_limits)
    assert u is not None
    np.testing.assert_allclose(sol.tau, u, atol=1e-6)
    # And the joint torques of the wrenches balance through the mechanism.
    tau_joints = uncoupled.maps().J.T @ sol.wrenches.ravel()
    lam, *_ = np.linalg.lstsq(A.T, tau_joints - S @ sol.tau, rcond=None)
    np.testing.assert_allclose(S @ sol.tau + A.T @ lam, tau_joints, atol=1e-9)


def test_the_uncoupled_optimum_is_not_the_coupled_one(hand):
    """The test above can fail: the uncoupled hand's actuator share is another torque."""
    setup, uncoupled, S, _ = hand
    free = solve(uncoupled)
    assert free.optimal
    assert np.max(np.abs(S.T @ free.tau - solve(setup).tau)) > 1e-3


@pytest.mark.parametrize('method', ['tau-qp-adaptive', 'force-qp', 'socp', 'nlp'])
def test_every_method_certifies_actuator_torques(hand, method):
    setup, _, _, _ = hand
    sol = solve(setup, method=method)
    assert sol.optimal, sol.message
    assert sol.tau.shape == (setup.hand.m,)
    assert_holds(setup, setup.maps(), sol.tau, sol.wrenches)
    assert np.linalg.norm(sol.tau) >= np.linalg.norm(solve(setup, method='socp').tau) - 1e-6


def test_capacity_and_min_max_equal_the_coupled_joint_torque_lps(hand):
    setup, uncoupled, S, A = hand
    lim = setup.hand.torque_limits
    cap = load_capacity(setup)
    alpha = coupled_lp(uncoupled, uncoupled.maps(), S, A, lim, load=setup.external_wrench)
    assert cap.value == pytest.approx(alpha, rel=1e-6)
    mm = solve(dataclasses.replace(setup, objective='min-max'))
    assert mm.optimal
    t = coupled_lp(uncoupled, uncoupled.maps(), S, A, lim)
    assert np.max(np.abs(mm.tau) / lim) == pytest.approx(t, rel=1e-6, abs=1e-9)


def test_explain_names_actuators_on_an_infeasible_coupled_load(hand):
    setup, uncoupled, S, A = hand
    heavy = dataclasses.replace(setup, external_wrench=setup.external_wrench * 200.0)
    sol = solve(heavy)
    assert sol.status == 'infeasible'
    why = explain(heavy)
    alpha = coupled_lp(uncoupled, uncoupled.maps(), S, A, setup.hand.torque_limits,
                       load=heavy.external_wrench)
    assert why.holdable_fraction == pytest.approx(alpha, rel=1e-6)
    assert all(name in setup.hand.joints for name, _ in why.capacity.binding.joints)


def test_score_ranks_coupled_candidates_as_single_solves(planar_doc, tmp_path):
    setup, _, _, _ = coupled(planar_doc, PLANAR_COUPLED)
    doc = copy.deepcopy(planar_doc)
    q = doc['grasp']['joint_positions']
    doc['hand'] = {'urdf': str((CONFIG / doc['hand']['urdf']).resolve()),
                   'joints': ['joint1', 'joint3'], 'torque_limits': [10.0, 10.0],
                   'coupling': {f: {'follows': t, 'multiplier': q[f] / q[t]}
                                for f, t in PLANAR_COUPLED}}
    for f, _ in PLANAR_COUPLED:
        del q[f]
    path = tmp_path / 'coupled.yaml'
    path.write_text(yaml.safe_dump(doc))
    loads = [[0.0, -1.0, 1.0, 0.5, 0.0, 0.0], [0.2, -0.5, 0.3, 0.1, 0.0, 0.0]]
    lines = [(i + 1, json.dumps({'id': str(i), 'load': {'external_wrench': w}}))
             for i, w in enumerate(loads)]
    records = score_batch(ScoreJob.from_file(path), lines, engine='serial')
    for rec, w in zip(records, loads):
        sol = solve(dataclasses.replace(setup, external_wrench=np.array(w)))
        assert rec['status'] == sol.status == 'optimal'
        assert rec['torque_norm'] == pytest.approx(sol.torque_norm, rel=1e-6)
