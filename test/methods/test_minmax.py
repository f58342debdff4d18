# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Min-max torque objective: certified, and no certified torque has a smaller max ratio."""

import copy
import dataclasses

from conftest import CONFIG, setup_from_doc
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.scenario import parse_scenario
from grasp_torque_opt.methods.dispatch import solve
from independent import assert_holds, lp_minmax
import numpy as np
import pytest

LOADS = [[1.4715, 0, 0, 0, 0, 0], [-1.4715, 0, 0, 0, 0, 0], [0, 1.4715, 0, 0, 0, 0],
         [0, 0, 1.4715, 0, 0.01, 0], [3.0, 0.5, -1.0, 0, 0, 0.005]]


def ratio(setup, tau, weights=None):
    w = np.ones(setup.hand.m) if weights is None else weights
    off = 0.0 if setup.torque_offset is None else setup.torque_offset
    return float((w * np.abs(tau + off) / setup.hand.torque_limits).max())


@pytest.mark.parametrize('load', LOADS)
def test_minmax_is_certified_and_optimal_against_a_force_space_lp(allegro, load):
    setup = dataclasses.replace(allegro, external_wrench=np.array(load, float),
                                objective='min-max')
    maps = setup.maps()
    sol = solve(setup, maps=maps)
    assert sol.optimal and sol.objective == 'min-max', sol.message
    assert_holds(setup, maps, sol.tau, sol.wrenches)
    best = lp_minmax(setup, maps)
    assert ratio(setup, sol.tau) <= best * (1 + 1e-6) + 1e-9
    assert ratio(setup, sol.tau) >= best * (1 - 1e-6) - 1e-9  # else the LP above is wrong
    assert sol.max_torque_ratio == pytest.approx(ratio(setup, sol.tau), rel=1e-12)
    # Among min-max optima it is the least effort, so never below the sum-of-squares optimum.
    sos = solve(dataclasses.replace(setup, objective='sum-of-squares'), maps=maps)
    assert sol.torque_norm >= sos.torque_norm - 1e-9
    assert ratio(setup, sos.tau) >= best * (1 - 1e-6) - 1e-9


def test_minmax_with_weights_and_a_torque_offset(allegro):
    rng = np.random.default_rng(3)
    weights = rng.uniform(0.5, 2.0, allegro.hand.m)
    offset = rng.uniform(-0.05, 0.05, allegro.hand.m)
    setup = dataclasses.replace(allegro, weights=weights, torque_offset=offset,
                                objective='min-max',
                                external_wrench=np.array([-1.4715, 0, 0, 0, 0, 0]))
    maps = setup.maps()
    sol = solve(setup, maps=maps)
    assert sol.optimal
    assert_holds(setup, maps, sol.tau, sol.wrenches)
    best = lp_minmax(setup, maps, weights)
    assert ratio(setup, sol.tau, weights) == pytest.approx(best, rel=1e-6, abs=1e-9)


def test_minmax_on_the_planar_hand(planar):
    setup = dataclasses.replace(planar, objective='min-max')
    maps = setup.maps()
    sol = solve(setup, maps=maps)
    assert sol.optimal
    assert ratio(setup, sol.tau) == pytest.approx(lp_minmax(setup, maps), rel=1e-6, abs=1e-9)


def test_an_infeasible_load_is_infeasible_for_minmax_too(allegro):
    setup = dataclasses.replace(allegro, objective='min-max',
                                external_wrench=10 * allegro.external_wrench)
    assert solve(setup).status == 'infeasible'


def test_the_objective_key_of_the_scenario(allegro_doc):
    doc = copy.deepcopy(allegro_doc)
    doc['objective'] = {'type': 'min-max'}
    assert setup_from_doc(doc).objective == 'min-max'
    doc['objective'] = {'type': 'minimax'}
    with pytest.raises(InputError, match='objective.type: must be one of sum-of-squares, '
                                         'min-max'):
        parse_scenario(doc, CONFIG)


def test_minmax_with_a_reference_method_is_refused(allegro):
    with pytest.raises(InputError, match='objective.type: min-max is solved by the tau-qp'):
        solve(dataclasses.replace(allegro, objective='min-max'), 'socp')


def test_minmax_equals_an_independent_lp_on_random_grasps(allegro):
    from test_capacity import random_grasps

    for setup in random_grasps(dataclasses.replace(allegro, objective='min-max'), 8, seed=12):
        maps = setup.maps()
        sol = solve(setup, maps=maps)
        best = lp_minmax(setup, maps)
        if best is None:
            assert sol.status == 'infeasible'
            continue
        assert sol.optimal, sol.message
        assert_holds(setup, maps, sol.tau, sol.wrenches)
        assert ratio(setup, sol.tau) == pytest.approx(best, rel=1e-6, abs=1e-9)


def test_the_min_max_lp_keeps_a_deadline(allegro):
    """
    The min-max objective's LP runs before the QP in the node's cycle, and keeps its deadline.

    On a 32-contact grasp it took up to 175 ms here, past a 50 ms budget. Under a deadline
    it stops by it, and none starts past it.
    """
    import time

    from grasp_torque_opt.core.scenario_fields import ContactSpec
    from grasp_torque_opt.core.tau_qp import build_tau_qp
    from grasp_torque_opt.methods.minmax import minmax_stage

    rng = np.random.default_rng(0)
    contacts = [ContactSpec(link=c.link, position=c.position + rng.normal(0, 2e-3, 3))
                for c in allegro.contacts * 8]
    big = dataclasses.replace(allegro, contacts=contacts,
                              external_wrench=allegro.external_wrench * 20)
    qp = build_tau_qp(big.maps(), big.friction, big.external_wrench, *big.tau_bounds,
                      big.weights)
    past = minmax_stage(qp, big.hand.torque_limits, big.weights,
                        deadline=time.perf_counter() - 1.0)
    assert past.status == 'failed' and 'time budget spent' in past.message
    t0 = time.perf_counter()
    minmax_stage(qp, big.hand.torque_limits, big.weights, deadline=t0 + 0.02)
    assert time.perf_counter() - t0 < 0.02 + 0.5
