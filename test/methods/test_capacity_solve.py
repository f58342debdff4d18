# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Scores and solves agree on planned boxes and cylinders (issue 38).

A capacity (the load's or an axis's) at or above a load means the tau-QP certifies
that load: the check is a solve of the scaled load, a formulation apart from the
capacity LP. The planned candidates include grasps that only balance their weight
(held over a range of loads that misses zero), where the capacity LP's top of the
range was not a load that solve certifies.
"""

import dataclasses
import json

from conftest import ALLEGRO
from grasp_torque_opt.core.object_geometry import ObjectShape
from grasp_torque_opt.methods.capacity import DIRECTIONS, load_capacity
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.methods.engines import score_batch
from grasp_torque_opt.methods.plan import plan_grasps, PlanSettings
from grasp_torque_opt.methods.score import merge, ScoreJob, Scorer
from independent import lp_feasible
import numpy as np
import pytest
import yaml

#: Objects planned: their shapes, masses [kg], how many candidates and the seed. A
#: cylinder grasp that cannot hold zero load but holds its weight is rare (one seed in
#: five gives one in 12 candidates); seed 10's include one with the IK of 5beab3a. A
#: planner change that loses it fails the last test below, saying so: then pick a seed
#: whose candidates have both kinds again.
OBJECTS = {'box': (ObjectShape('box', np.array([0.05, 0.04, 0.06])), 0.10, 4, 7),
           'cylinder': (ObjectShape('cylinder', np.array([0.025, 0.08])), 0.12, 12, 10)}
#: Below 1: the largest multiple checked sits just inside the capacity.
INSIDE = 1 - 1e-6


@pytest.fixture(scope='module')
def planned():
    """(object, friction margin, candidate line, record) of every planned candidate."""
    out = []
    base = yaml.safe_load(ALLEGRO.read_text())
    for kind, (shape, mass, count, seed) in OBJECTS.items():
        # Uniform orientations, every touching candidate kept (the planner's defaults
        # keep only held ones): the grasps that only balance their weight are wanted here.
        plan = plan_grasps(ALLEGRO, PlanSettings(count=count, seed=seed, orientation='random',
                                                 hold_margin=None), shape=shape, mass=mass)
        assert len(plan.candidates) == count
        for margin in (0.0, 0.3):
            job = ScoreJob(scenario_text=yaml.safe_dump(merge(
                base, {'friction': {'margin': margin}})), base_dir=str(ALLEGRO.parent))
            lines = [(i, json.dumps(c)) for i, c in enumerate(plan.candidates, 1)]
            records = score_batch(job, lines, engine='serial')
            scorer = Scorer(job)
            out += [(kind, margin, scorer.candidate(n, text)[1], rec)
                    for (n, text), rec in zip(lines, records)]
    return out


def certifies(setup, load) -> bool:
    """Return whether the tau-QP certifies torques holding this load."""
    return solve(dataclasses.replace(setup, external_wrench=np.asarray(load, float)),
                 backend='daqp').optimal


def test_an_axis_capacity_at_or_above_a_load_is_a_load_solve_certifies(planned):
    checked = 0
    for kind, margin, setup, rec in planned:
        weight = float(np.abs(setup.external_wrench).max())
        for name, cap in rec['capacities'].items():
            if not cap:
                continue
            i, sign = DIRECTIONS[name]
            d = np.zeros(6)
            d[i] = sign
            sizes = [INSIDE * cap] + ([weight] if name[1] == 'F' and cap >= weight else [])
            for size in sizes:  # the capacity's top, and the weight along the axis
                assert certifies(setup, size * d), (kind, margin, rec['id'], name, size)
                checked += 1
    assert checked > 100


def test_a_load_capacity_of_one_or_more_is_a_load_solve_certifies(planned):
    for kind, margin, setup, rec in planned:
        cap = rec['capacity']
        where = (kind, margin, rec['id'])
        assert cap is not None, where
        if rec['status'] == 'infeasible':
            assert cap < 1 and rec['holdable_fraction'] == cap, where
        if cap > 0:
            assert certifies(setup, INSIDE * cap * setup.external_wrench), where
            assert certifies(setup, np.zeros(6)), where
        if cap >= 1:
            assert rec['status'] == 'optimal', where


def test_a_held_load_has_capacity_one_unless_zero_load_is_not_held(planned):
    """The converse, with HiGHS's zero-load LP as the independent judge of the exception."""
    kinds = set()
    for kind, margin, setup, rec in planned:
        zero = lp_feasible(dataclasses.replace(
            setup, friction=dataclasses.replace(setup.friction, margin=0.0, mu1=setup.friction.mu1
                                                / (1 + margin), mu2=setup.friction.mu2
                                                / (1 + margin)),
            external_wrench=np.zeros(6)), setup.maps())
        where = (kind, margin, rec['id'])
        if rec['status'] == 'optimal':
            assert (rec['capacity'] >= 1 - 1e-9) == zero, where
        if not zero:
            assert (rec['capacity'], rec['capacity_status']) == (0.0, 'infeasible'), where
            assert set(rec['capacities'].values()) == {0.0}, where
            kinds.add((kind, rec['status']))
    # The plans hold both kinds of such grasps: one whose load is held, one whose not.
    assert ('cylinder', 'optimal') in kinds and ('cylinder', 'infeasible') in kinds, (
        f'the planned cylinders lack a kind of grasp that cannot hold zero load: {kinds}')


def test_the_planners_unconfirmed_capacity_is_the_confirmed_one(planned):
    """
    ``confirm=False`` (the planner's filter: DAQP alone on zero load) gives HiGHS's verdict.

    Each planned grasp's capacity with and without the confirmation (HiGHS behind DAQP,
    the independent feasibility LP) has the same status and value, zero load not held
    among them.
    """
    statuses = []
    for kind, margin, setup, rec in planned:
        alone = load_capacity(setup, explain=False, confirm=False)
        confirmed = load_capacity(setup, explain=False)
        where = (kind, margin, rec['id'], alone.message, confirmed.message)
        assert alone.status == confirmed.status, where
        if confirmed.value is None:
            assert alone.value is None, where
        else:
            assert alone.value == pytest.approx(confirmed.value, rel=1e-6, abs=1e-9), where
        statuses.append(confirmed.status)
    assert statuses.count('infeasible') >= 3 and statuses.count('optimal') >= 3, statuses
