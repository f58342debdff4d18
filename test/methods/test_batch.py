# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Batch scoring's stages give the single path's records, candidate for candidate.

Hundreds of candidates (moved joints, random loads, loads no grasp holds, other
contacts, bad lines, lines with fields the stages leave to the single path) are scored
by :class:`BatchScorer` and one by one by :meth:`Scorer.score_line`; the records must
agree: the same status, error and id, torques, wrenches and metrics within 1e-7.
"""

import json

from conftest import ALLEGRO
from grasp_torque_opt.control import compiled
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.tree_kinematics import TreeKinematics
from grasp_torque_opt.methods.batch import BatchScorer
from grasp_torque_opt.methods.engines import score_batch
from grasp_torque_opt.methods.score import ScoreJob, Scorer
from grasp_torque_opt.native import loader
import numpy as np
import pytest

pytestmark = pytest.mark.skipif(not compiled.available(), reason=loader.IMPORT_ERROR)

THREE = [{'link': 'link_3.0_tip', 'position': [0.0072, -0.0051, 0.0081]},
         {'link': 'link_7.0_tip', 'position': [0.0120, 0.0, -0.0011],
          'normal': [0.3, 0.1, -1.0], 'tangent': [1.0, 0.0, 0.0]},
         {'link': 'link_15.0_tip', 'position': [0.0072, -0.0052, 0.0081]}]


def candidates(count: int, seed: int) -> list[tuple[int, str]]:
    """Lines of every kind, numbered from 1 (written here, not bench/candidates.py)."""
    base = GraspSetup.from_file(ALLEGRO)
    hand = base.hand
    rng = np.random.default_rng(seed)
    q0 = base.q[hand.idx_q]
    out = []
    for i in range(count):
        q = q0 + rng.uniform(-0.08, 0.08, hand.m)
        line = {'id': f'c{i}', 'grasp': {'joint_positions': {
            j: float(x) for j, x in zip(hand.joints, q)}}}
        kind = i % 10
        if kind in (1, 2, 3):  # a random load instead of the weight; some too heavy
            scale = 40.0 if kind == 3 else 2.0
            w = rng.normal(size=6) * [scale] * 3 + rng.normal(size=6) * [0.0] * 3
            w[3:] = rng.normal(size=3) * 0.02
            line.update(gravity=None, load={'external_wrench': w.tolist()})
        elif kind == 4:  # three contacts, one with a normal and a tangent
            line['grasp']['contacts'] = THREE
        elif kind == 5:  # the weight plus an extra load
            line['load'] = {'external_wrench': rng.normal(size=6).tolist()}
        elif kind == 6 and i % 20 == 6:  # fields the stages leave to the single path
            line['friction'] = {'margin': 0.1}
        elif kind == 7 and i % 20 == 7:  # bad lines of several kinds
            line = [{'grasp': {'joint_positions': {'joint_99': 0}}},
                    {'grasp': {'contacts': [{'link': 'no_such_tip'}]}},
                    {'load': {'external_wrench': [1, 2]}},
                    {'gravity': None}][(i // 20) % 4]
        out.append((i + 1, json.dumps(line)))
    out.append((count + 1, '{not json'))
    out.append((count + 2, '{"grasp": {"joint_positions": {"joint_1.0": true}}}'))
    out.append((count + 3, '{"load": {"external_wrench": [1e400, 0, 0, 0, 0, 0]}}'))
    return out


def assert_same(fast: list, slow: list, tol: float = 1e-7) -> None:
    assert len(fast) == len(slow)
    for a, b in zip(fast, slow):
        assert a.keys() == b.keys(), (a['line'], a.keys() ^ b.keys())
        for key in ('line', 'id', 'status', 'error', 'backend', 'capacity_status',
                    'capacity_reason'):
            assert a.get(key) == b.get(key), (a['line'], key, a.get(key), b.get(key))
        for key in ('torque_norm', 'max_torque_ratio', 'friction_usage_max', 'capacity',
                    'holdable_fraction'):
            if b.get(key) is None:
                assert a.get(key) is None, (a['line'], key)
            else:
                assert a[key] == pytest.approx(b[key], rel=tol, abs=tol), (a['line'], key)
        for key in ('tau', 'wrenches', 'friction_usage'):
            if b.get(key) is None:
                assert a.get(key) is None
            else:
                np.testing.assert_allclose(a[key], b[key], rtol=tol, atol=tol,
                                           err_msg=f"line {a['line']} {key}")
        for k, v in (b.get('capacities') or {}).items():
            assert (a['capacities'][k] is None) == (v is None), (a['line'], k)
            if v is not None:
                assert a['capacities'][k] == pytest.approx(v, rel=tol, abs=tol)


def test_the_batch_stages_give_the_single_paths_records_on_hundreds_of_candidates():
    job = ScoreJob.from_file(ALLEGRO, metrics='basic', solutions=True)
    lines = candidates(400, seed=3)
    batch = BatchScorer(Scorer(job))
    assert batch.why_not == ''
    fast = batch.score_lines(lines)
    slow = Scorer(job).score_lines(lines)
    assert_same(fast, slow)
    status = [r['status'] for r in slow]
    # Every kind is there: held, not holdable (confirmed by the single path's LP), bad.
    assert status.count('optimal') > 250 and status.count('infeasible') >= 10
    assert status.count('error') >= 10
    # And the stages answered the candidates they take (not the single path throughout).
    margin = [r['status'] for (_, text), r in zip(lines, slow) if '"friction"' in text]
    assert margin and set(margin) == {'optimal'}  # these the single path answers
    assert batch.staged == status.count('optimal') - len(margin)
    assert batch.staged + batch.single == len(lines)


def test_full_metrics_match_the_single_path():
    job = ScoreJob.from_file(ALLEGRO, metrics='full')
    lines = candidates(30, seed=4)
    batch = BatchScorer(Scorer(job))
    fast = batch.score_lines(lines)
    assert batch.staged > 15
    assert_same(fast, Scorer(job).score_lines(lines), tol=1e-6)


def test_score_batch_runs_the_batch_stages_in_every_engine():
    job = ScoreJob.from_file(ALLEGRO, metrics='basic')
    lines = candidates(60, seed=5)
    serial = score_batch(job, lines, engine='serial', chunk=16)
    pool = score_batch(job, lines, engine='processes', workers=2, chunk=16)
    assert_same(pool, serial, tol=1e-9)
    assert [r['rank'] for r in pool] == [r['rank'] for r in serial]
    # score_batch ranks its records; a Scorer's records are unranked.
    assert_same([{k: v for k, v in r.items() if k != 'rank'} for r in serial],
                Scorer(job).score_lines(lines))


def test_jobs_outside_the_stages_take_the_single_path_and_say_why():
    job = ScoreJob.from_file(ALLEGRO, metrics='basic', backend='proxsuite')
    batch = BatchScorer(Scorer(job))
    assert 'proxsuite' in batch.why_not
    lines = candidates(12, seed=6)
    assert_same(batch.score_lines(lines), Scorer(job).score_lines(lines))
    assert batch.staged == 0
    minmax = BatchScorer(Scorer(ScoreJob.from_file(ALLEGRO, objective='min-max')))
    assert 'min-max' in minmax.why_not


@pytest.mark.parametrize('module', [None, 'compiled'])
def test_tree_kinematics_equal_pinocchios(module):
    setup = GraspSetup.from_file(ALLEGRO)
    kin = TreeKinematics(setup.hand.model, loader.fast_cycle if module else None)
    rng = np.random.default_rng(7)
    Q = setup.q + rng.uniform(-1.5, 1.5, (25, setup.hand.model.nq))
    frames = tuple(range(1, setup.hand.model.nframes))  # every frame, not only the tips
    assert kin.check(Q, frames, tol=1e-12) <= 1e-12


CHAIN = """<robot name="chain">
  <link name="base"/><link name="a"/><link name="b"/><link name="c"/>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="a"/>
    <origin xyz="0.1 0.02 0" rpy="0.3 0 0.2"/><axis xyz="0.6 0 0.8"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="hinge" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0 0.05 0.01" rpy="0 0.4 0"/><axis xyz="0.2 0.5 -0.3"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="tip" type="fixed"><parent link="b"/><child link="c"/>
    <origin xyz="0.03 0 0.04" rpy="0.1 0.2 0.3"/></joint>
</robot>"""


@pytest.mark.parametrize('module', [None, 'compiled'])
def test_tree_kinematics_take_prismatic_joints_and_unaligned_axes(module):
    import pinocchio as pin

    model = pin.buildModelFromXML(CHAIN)
    kin = TreeKinematics(model, loader.fast_cycle if module else None)
    Q = np.random.default_rng(8).uniform(-1.0, 1.0, (30, model.nq))
    assert kin.check(Q, tuple(range(model.nframes)), tol=1e-12) <= 1e-12


def test_a_hand_with_coupled_joints_takes_the_single_path():
    from conftest import CONFIG

    job = ScoreJob.from_file(CONFIG / 'ability_right.yaml', metrics='basic')
    batch = BatchScorer(Scorer(job))
    assert batch.why_not  # coupled joints, or a joint the stages do not take
    lines = [(1, '{}'), (2, '{"gravity": null, "load": {"external_wrench": [0, 0, 1, 0, 0, 0]}}')]
    assert_same(batch.score_lines(lines), Scorer(job).score_lines(lines))


def test_the_planar_hand_scores_as_the_single_path():
    from conftest import CONFIG

    job = ScoreJob.from_file(CONFIG / 'planar_two_finger.yaml', metrics='full')
    rng = np.random.default_rng(9)
    lines = [(i + 1, json.dumps({'gravity': None, 'load': {
        'external_wrench': (rng.normal(size=6) * [2, 2, 2, 0.01, 0.01, 0.01]).tolist()}}))
        for i in range(40)]
    batch = BatchScorer(Scorer(job))
    assert_same(batch.score_lines(lines), Scorer(job).score_lines(lines), tol=1e-6)
    # Two contacts: A = [G; J^T] has internal-force directions (not of full column rank),
    # which the compiled build hands back: every line takes the single path.
    assert batch.single == len(lines) and batch.staged == 0
