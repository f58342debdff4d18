# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Friction margin: the scenario key, the reduced cone, and usage on the unreduced one."""

import copy
import dataclasses

from conftest import CONFIG, setup_from_doc
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.margin import cone_usage, planned_friction, torque_ratio
from grasp_torque_opt.core.scenario import Friction, parse_scenario
from grasp_torque_opt.methods.dispatch import solve
from independent import assert_holds
import numpy as np
import pytest


def test_planned_friction_divides_both_coefficients_by_one_plus_k():
    fr = Friction(0.5, 0.005, 8, 0.5, margin=0.25)
    p = planned_friction(fr)
    assert (p.mu1, p.mu2, p.sides, p.min_normal_force, p.margin) == (0.4, 0.004, 8, 0.5, 0.0)
    unmargined = Friction(0.5, 0.005, 8)
    assert planned_friction(unmargined) is unmargined


def test_cone_usage_is_one_on_the_cone_and_inf_without_pressing():
    mu1, mu2 = 0.5, 0.01
    on = [0.3 * mu1, 0.4 * mu1, 1.0, 0.3 * mu2]  # |f_t| = 0.5 mu1, |m_z| = 0.3 mu2 ... + = 0.8
    np.testing.assert_allclose(cone_usage([on, [0, 0, 2, 0], [1, 0, 0, 0]], mu1, mu2),
                               [0.8, 0.0, np.inf])


def test_torque_ratio_counts_the_offset_and_the_weights():
    assert torque_ratio(np.array([0.1, -0.3]), np.array([1.0, 0.5])) == pytest.approx(0.6)
    assert torque_ratio(np.array([0.1, -0.3]), np.array([1.0, 0.5]),
                        offset=np.array([0.0, -0.1])) == pytest.approx(0.8)
    assert torque_ratio(np.array([0.1, -0.3]), np.array([1.0, 0.5]),
                        weights=np.array([10.0, 1.0])) == pytest.approx(1.0)


@pytest.mark.parametrize('value, problem', [(-0.1, 'must be >= 0'), ('x', 'must be a number'),
                                            (float('inf'), 'must be finite')])
def test_a_bad_margin_names_the_field(allegro_doc, value, problem):
    doc = copy.deepcopy(allegro_doc)
    doc['friction']['margin'] = value
    with pytest.raises(InputError, match=f'friction.margin: {problem}'):
        parse_scenario(doc, CONFIG)


@pytest.mark.parametrize('k', [0.1, 0.25, 1.0])
def test_margined_torques_satisfy_the_reduced_cone(allegro_doc, k):
    doc = copy.deepcopy(allegro_doc)
    doc['friction']['margin'] = k
    setup = setup_from_doc(doc)
    maps = setup.maps()
    sol = solve(setup, maps=maps)
    assert sol.optimal and sol.friction_margin == k
    # Independent: the exact cone of mu/(1+k), written here, not the package's reduction.
    fr = setup.friction
    reduced = dataclasses.replace(setup, friction=Friction(fr.mu1 / (1 + k), fr.mu2 / (1 + k),
                                                           fr.sides, fr.min_normal_force))
    assert_holds(reduced, maps, sol.tau, sol.wrenches)
    w = sol.wrenches
    usage = (np.hypot(w[:, 0], w[:, 1]) / fr.mu1 + np.abs(w[:, 3]) / fr.mu2) / w[:, 2]
    np.testing.assert_allclose(sol.friction_usage, usage, rtol=1e-12)
    assert usage.max() <= 1 / (1 + k) + 1e-7
    # The unmargined optimum uses more of the cone than the margin allows.
    plain = solve(dataclasses.replace(setup, friction=dataclasses.replace(fr, margin=0.0)),
                  maps=maps)
    assert plain.friction_usage.max() > 1 / (1 + k) + 1e-3


def test_the_adaptive_method_plans_with_the_margin_too(allegro):
    k = 0.25
    setup = dataclasses.replace(allegro, friction=dataclasses.replace(allegro.friction,
                                                                      margin=k))
    sol = solve(setup, 'tau-qp-adaptive')
    assert sol.optimal and sol.friction_margin == k
    assert sol.friction_usage.max() <= 1 / (1 + k) + 1e-7
