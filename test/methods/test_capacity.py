# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Load capacity: every load from zero to alpha held, none just above, by independent solvers."""

import copy
import dataclasses

import box_grasp
from conftest import setup_from_doc
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.methods.capacity import direction_capacities, DIRECTIONS, load_capacity
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.methods.explain import explain
from independent import assert_holds, lp_alpha_range, lp_capacity, lp_feasible
import numpy as np
import pytest


def holds(setup, maps, load) -> bool:
    """Return whether the tau-QP certifies torques for this load."""
    return solve(dataclasses.replace(setup, external_wrench=np.asarray(load, float)),
                 maps=maps, backend='daqp').optimal


def reduced(setup):
    """Return the setup with the cone of mu/(1+k) and no margin, written here."""
    fr, k = setup.friction, setup.friction.margin
    return dataclasses.replace(setup, friction=dataclasses.replace(
        fr, mu1=fr.mu1 / (1 + k), mu2=fr.mu2 / (1 + k), margin=0.0))


def above_is_infeasible(setup, maps, load) -> bool:
    """Say if HiGHS (test/independent.py) finds no wrench for this load in the planned cones."""
    return not lp_feasible(dataclasses.replace(reduced(setup),
                                               external_wrench=np.asarray(load, float)), maps)


@pytest.mark.parametrize('margin', [0.0, 0.3])
def test_allegro_capacity_holds_at_alpha_and_not_just_above(allegro_doc, margin):
    doc = copy.deepcopy(allegro_doc)
    doc['friction']['margin'] = margin
    setup = setup_from_doc(doc)
    maps = setup.maps()
    cap = load_capacity(setup, maps)
    assert cap.status == 'optimal' and cap.certificate.ok and cap.value > 1
    w = setup.external_wrench
    for s in (0.0, 0.5, 1 - 1e-6):  # the whole range from zero
        assert holds(setup, maps, s * cap.value * w), s
    assert above_is_infeasible(setup, maps, (1 + 1e-4) * cap.value * w)
    # The LP's own holding wrenches, checked independently at alpha w_ext.
    assert_holds(dataclasses.replace(reduced(setup), external_wrench=cap.value * w), maps,
                 cap.tau, cap.wrenches)
    alpha, _ = lp_capacity(setup, maps, w)
    assert cap.value == pytest.approx(alpha, rel=1e-6)
    assert load_capacity(setup, maps, highs_only=True).value == pytest.approx(alpha, rel=1e-6)


def test_a_margin_lowers_the_capacity(allegro):
    maps = allegro.maps()
    plain = load_capacity(allegro, maps).value
    fr = dataclasses.replace(allegro.friction, margin=0.5)
    assert load_capacity(dataclasses.replace(allegro, friction=fr), maps).value < plain


def test_axis_capacities_hold_at_their_value_and_not_above(allegro):
    maps = allegro.maps()
    caps = direction_capacities(allegro, maps)
    assert list(caps) == list(DIRECTIONS) and len(caps) == 12
    for name, cap in caps.items():
        i, sign = DIRECTIONS[name]
        d = np.zeros(6)
        d[i] = sign
        assert cap.status == 'optimal', (name, cap.message)
        assert cap.unit == ('N' if name[1] == 'F' else 'N m')
        for s in (0.0, 0.5, 1 - 1e-6):
            assert holds(allegro, maps, s * cap.value * d), (name, s)
        assert above_is_infeasible(allegro, maps, (1 + 1e-4) * cap.value * d), name


def test_planar_capacity_with_internal_forces(planar):
    """The rank-deficient planar hand (null-space internal forces): the same two checks."""
    maps = planar.maps()
    cap = load_capacity(planar, maps)
    assert cap.status == 'optimal' and cap.certificate.ok
    w = planar.external_wrench
    assert holds(planar, maps, (1 - 1e-6) * cap.value * w)
    assert above_is_infeasible(planar, maps, (1 + 1e-4) * cap.value * w)


def test_capacity_zero_when_not_even_zero_load_holds(allegro_doc):
    doc = copy.deepcopy(allegro_doc)
    doc['friction']['min_normal_force'] = 50.0  # no joint can squeeze this hard
    setup = setup_from_doc(doc)
    maps = setup.maps()
    assert not lp_feasible(dataclasses.replace(setup, external_wrench=np.zeros(6)), maps)
    cap = load_capacity(setup, maps)
    assert cap.status == 'infeasible' and cap.value == 0.0
    assert cap.conflict is not None and cap.conflict.certified
    assert 'minimum normal force' in cap.message
    for name, c in direction_capacities(setup, maps).items():
        assert (c.status, c.value) == ('infeasible', 0.0), name
        assert c.unit == ('N' if name[1] == 'F' else 'N m')


@pytest.mark.parametrize('scale', [1e-200, 1e-6, 1e6, 1e200])
def test_the_capacity_scales_with_the_load(allegro, scale):
    """alpha(s w) = alpha(w) / s: the LP runs on the unit direction whatever the load's size."""
    maps = allegro.maps()
    base = load_capacity(allegro, maps).value
    cap = load_capacity(allegro, maps, load=scale * allegro.external_wrench)
    assert cap.status == 'optimal' and cap.value == pytest.approx(base / scale, rel=1e-9)


def test_a_zero_load_has_no_finite_capacity(allegro):
    assert load_capacity(allegro, load=np.zeros(6)).status == 'unbounded'


def random_grasps(base, count, seed):
    """Seeded grasps near the bundled one: joints moved up to 0.08 rad, a random load."""
    rng = np.random.default_rng(seed)
    hand = base.hand
    for _ in range(count):
        q = base.q.copy()
        q[hand.idx_q] += rng.uniform(-0.08, 0.08, hand.m)
        d = rng.normal(size=3)
        w = np.concatenate((1.47 * rng.uniform(0.3, 2.0) * d / np.linalg.norm(d),
                            rng.normal(size=3) * 0.004))
        yield dataclasses.replace(base, q=q, external_wrench=w)


def test_capacity_equals_an_independent_lp_on_random_grasps(allegro):
    for setup in random_grasps(allegro, 8, seed=11):
        maps = setup.maps()
        cap = load_capacity(setup, maps)
        alpha, _ = lp_capacity(setup, maps, setup.external_wrench)
        assert cap.status == 'optimal' and cap.certificate.ok
        assert cap.value == pytest.approx(alpha, rel=1e-6)


def test_the_unexplained_capacity_is_the_same_verdict_against_an_independent_lp(allegro_doc):
    """The planner's filter (explain=False, no binding): the same status and value."""
    doc = copy.deepcopy(allegro_doc)
    doc['friction']['min_normal_force'] = 50.0
    setups = [*random_grasps(setup_from_doc(allegro_doc), 6, seed=12), setup_from_doc(doc)]
    for setup in setups:
        maps = setup.maps()
        cap = load_capacity(setup, maps, explain=False)
        full = load_capacity(setup, maps)
        assert (cap.status, cap.value) == (full.status, full.value)
        assert cap.conflict is None and cap.binding is None
        if cap.status == 'optimal':
            assert cap.value == pytest.approx(lp_capacity(setup, maps,
                                                          setup.external_wrench)[0], rel=1e-6)
        else:
            assert cap.status == 'infeasible'
            assert not lp_feasible(dataclasses.replace(setup, external_wrench=np.zeros(6)),
                                   maps)


def box_setup(tmp_path, mz: float) -> GraspSetup:
    """
    Return the box held by two fingers and an offset thumb, mu 0.3, under a moment Mz.

    Its squeeze makes a moment about +z that friction cannot balance (test/box_grasp.py):
    zero load is not holdable, a load of -Mz large enough is.
    """
    doc = box_grasp.scenario()
    doc['load']['external_wrench'] = [0.0, 0.0, 0.0, 0.0, 0.0, mz]
    return GraspSetup.from_file(box_grasp.write(tmp_path, doc))


@pytest.mark.parametrize('mz', [-0.01, -0.04])
def test_a_load_range_that_misses_zero_gives_capacity_zero(tmp_path, mz):
    setup = box_setup(tmp_path, mz)
    maps = setup.maps()
    w = setup.external_wrench
    lo, hi = lp_alpha_range(setup, maps, w)
    assert 0 < lo < hi  # HiGHS: multiples from lo to hi are held, none below lo
    assert not lp_feasible(dataclasses.replace(setup, external_wrench=np.zeros(6)), maps)
    assert holds(setup, maps, 2 * lo * w)  # the tau-QP agrees that some are
    assert solve(setup, maps=maps).status == ('optimal' if lo <= 1 else 'infeasible')
    cap = load_capacity(setup, maps)
    assert (cap.status, cap.value) == ('infeasible', 0.0)
    assert cap.conflict.certified and 'not even zero load' in cap.message
    axis = direction_capacities(setup, maps)['-Mz']  # held from 0.016 N m, not from 0
    assert lp_alpha_range(setup, maps, np.array([0, 0, 0, 0, 0, -1.0]))[0] > 0
    assert (axis.status, axis.value, axis.unit) == ('infeasible', 0.0, 'N m')
    why = explain(setup, maps)
    assert why.holdable_fraction == 0.0 and why.text == cap.message
