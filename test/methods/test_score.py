# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Batch scoring: the batch's scores equal single solves.

Bad lines are named and skipped, and the process pool and a local Dask cluster give the
serial answers.
"""

import copy
import dataclasses
import json
import subprocess
import sys

import box_grasp
from conftest import ALLEGRO
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.methods.capacity import direction_capacities, load_capacity
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.methods.engines import score_batch
from grasp_torque_opt.methods.ranking import rank
from grasp_torque_opt.methods.score import merge, ScoreJob
from independent import assert_holds, lp_alpha_range, lp_feasible
import numpy as np
import pytest
import yaml

MOVED = {'joint_1.0': 0.12, 'joint_13.0': 0.6}
GOOD = [
    {'id': 'as-is'},
    {'id': 'moved', 'grasp': {'joint_positions': MOVED}},
    {'id': 'load', 'gravity': None, 'load': {'external_wrench': [0, 0.5, -1.0, 0, 0.01, 0]}},
    {'id': 'heavy', 'object': {'mass': 1.5}},  # ten times the ball: infeasible
    {'id': 'margin', 'friction': {'margin': 0.2}},
    {'id': 'minmax', 'objective': {'type': 'min-max'}},
    {'id': 'three', 'grasp': {'contacts': [{'link': 'link_3.0_tip',
                                            'position': [0.0072, -0.0051, 0.0081]},
                                           {'link': 'link_7.0_tip',
                                            'position': [0.0120, 0.0, -0.0011]},
                                           {'link': 'link_15.0_tip',
                                            'position': [0.0072, -0.0052, 0.0081]}]}},
]
BAD = [  # (line text, what the error must name)
    ('{not json', 'not valid JSON'),
    ('["a list"]', 'must be a JSON object'),
    ('{"hand": {"urdf": "x.urdf"}}', 'hand: unknown or fixed field'),
    ('{"friction": {"mu_tangential": -1}}', 'friction.mu_tangential: must be > 0'),
    ('{"grasp": {"contacts": [{"link": "no_such_tip"}]}}', 'grasp.contacts[0].link'),
    ('{"grasp": {"joint_positions": {"joint_99": 0}}}', 'grasp.joint_positions.joint_99'),
    ('{"objective": {"weights": [1, 2]}}', 'objective.weights'),
    ('{"load": {"external_wrench": [NaN, 0, 0, 0, 0, 0]}}', 'load.external_wrench[0]: must be '
                                                            'finite'),
    ('[' * 100_000 + ']' * 100_000, 'nested too deeply'),
    ('{"grasp": {"contacts": []}}', 'grasp.contacts: must be a non-empty list'),
    ('{"object": {"mass": 1e400}}', 'object.mass'),
]


def independent_merge(base, over):
    """Merge by the documented rule, written again: mappings merge, null removes, else replace."""
    out = copy.deepcopy(base)
    for k, v in over.items():
        if v is None:
            out.pop(k, None)
        elif isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = independent_merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


@pytest.fixture(scope='module')
def job():
    return ScoreJob.from_file(ALLEGRO)


@pytest.fixture(scope='module')
def lines():
    return [(i + 1, json.dumps(c)) for i, c in enumerate(GOOD)]


def test_batch_scores_equal_single_solves(job, lines, tmp_path, allegro_doc):
    records = score_batch(job, lines, engine='serial')
    assert [r['id'] for r in records] == [c['id'] for c in GOOD]
    for cand, rec in zip(GOOD, records):
        over = {k: v for k, v in cand.items() if k != 'id'}
        doc = independent_merge(allegro_doc, over)
        path = tmp_path / f"{cand['id']}.yaml"
        doc['hand']['urdf'] = allegro_doc['hand']['urdf']
        path.write_text(yaml.safe_dump(doc))
        setup = GraspSetup.from_file(path)
        maps = setup.maps()
        sol = solve(setup, maps=maps, backend='daqp')
        assert rec['status'] == sol.status, cand['id']
        cap = load_capacity(setup, maps)
        assert rec['capacity'] == pytest.approx(cap.value, rel=1e-9), cand['id']
        caps = direction_capacities(setup, maps)
        for k, c in caps.items():
            assert rec['capacities'][k] == pytest.approx(c.value, rel=1e-9), (cand['id'], k)
        if sol.optimal:
            assert rec['torque_norm'] == pytest.approx(sol.torque_norm, rel=1e-9)
            assert rec['max_torque_ratio'] == pytest.approx(sol.max_torque_ratio, rel=1e-9)
            np.testing.assert_allclose(rec['friction_usage'], sol.friction_usage, rtol=1e-9)
            assert rec['holdable_fraction'] is None
        else:
            assert rec['torque_norm'] is None and rec['holdable_fraction'] == rec['capacity'] < 1
        assert (rec['capacity_reason'] is None) == (cap.status == 'optimal'), cand['id']
    by_id = {r['id']: r for r in records}
    assert by_id['heavy']['status'] == 'infeasible'
    assert by_id['margin']['friction_usage_max'] <= 1 / 1.2 + 1e-7
    assert by_id['three']['status'] == 'optimal' and len(by_id['three']['friction_usage']) == 3


def test_a_grasp_that_holds_no_zero_load_scores_capacity_zero(tmp_path):
    """The offset-thumb box (test/box_grasp.py): -Mz loads held from some size on only."""
    job = ScoreJob.from_file(box_grasp.write(tmp_path, box_grasp.scenario()))
    loads = {'small': -0.01, 'large': -0.04}  # N m about z: infeasible, then optimal
    records = score_batch(job, [{'id': k, 'load': {'external_wrench': [0, 0, 0, 0, 0, v]}}
                                for k, v in loads.items()], engine='serial')
    setup = GraspSetup.from_file(tmp_path / 'box.yaml')
    maps = setup.maps()
    assert not lp_feasible(dataclasses.replace(setup, external_wrench=np.zeros(6)), maps)
    for rec in records:
        w = np.array([0, 0, 0, 0, 0, loads[rec['id']]])
        lo, _ = lp_alpha_range(setup, maps, w)  # HiGHS: held from lo times w, not below
        assert rec['status'] == ('optimal' if lo <= 1 else 'infeasible'), rec['id']
        assert (rec['capacity'], rec['capacity_status']) == (0.0, 'infeasible')
        assert 'not even zero load' in rec['capacity_reason']
        assert set(rec['capacities'].values()) == {0.0}
        assert rec['holdable_fraction'] == (0.0 if rec['status'] == 'infeasible' else None)


def test_bad_lines_name_line_and_field_and_the_batch_goes_on(job):
    texts = [json.dumps(GOOD[0])] + [t for t, _ in BAD] + [json.dumps(GOOD[1])]
    records = score_batch(job, list(enumerate(texts, 1)), engine='serial')
    assert len(records) == len(texts)
    assert records[0]['status'] == records[-1]['status'] == 'optimal'
    for rec, (_, expected) in zip(records[1:-1], BAD):
        assert rec['status'] == 'error'
        assert rec['error'].startswith(f"line {rec['line']}: "), rec['error']
        assert expected in rec['error'], rec['error']
        assert '\n' not in rec['error']


def test_merge_copies_only_what_changes():
    base = {'a': {'b': 1, 'c': [1, 2]}, 'd': 2}
    out = merge(base, {'a': {'b': 3}, 'd': None})
    assert out == {'a': {'b': 3, 'c': [1, 2]}} and base == {'a': {'b': 1, 'c': [1, 2]}, 'd': 2}


def test_ranking_puts_optimal_first_by_capacity(job, lines):
    ranked = rank(score_batch(job, lines, engine='serial'))
    caps = [r['capacity'] for r in ranked if r['status'] == 'optimal']
    assert caps == sorted(caps, reverse=True)
    assert ranked[-1]['status'] == 'infeasible'


def test_the_process_pool_gives_the_serial_records(job, lines):
    serial = score_batch(job, lines, engine='serial')
    seen = []
    pooled = score_batch(job, lines, engine='processes', workers=2, chunk=2,
                         progress=lambda done, total: seen.append((done, total)))
    drop = ('time_s', 'solve_time_s')
    # Equal to the solvers' precision: the batch stages warm-start each QP from its
    # neighbour in the chunk, and the chunks differ.
    assert [{k: rounded(v) for k, v in r.items() if k not in drop} for r in pooled] == \
        [{k: rounded(v) for k, v in r.items() if k not in drop} for r in serial]
    assert seen[-1] == (len(lines), len(lines))


def rounded(v):
    """Return v with every float to 9 significant digits (lists and dicts too)."""
    if isinstance(v, float):
        return float(f'{v:.9g}')
    if isinstance(v, (list, tuple)):
        return [rounded(x) for x in v]
    if isinstance(v, dict):
        return {k: rounded(x) for k, x in v.items()}
    return v


def test_a_local_dask_cluster_gives_the_serial_records(job, lines):
    pytest.importorskip('distributed')
    serial = score_batch(job, lines, engine='serial')
    dask = score_batch(job, lines, engine='dask', workers=2, chunk=3)
    assert [rounded((r['id'], r['status'], r['capacity'], r['torque_norm'])) for r in dask] == \
        [rounded((r['id'], r['status'], r['capacity'], r['torque_norm'])) for r in serial]


def test_in_memory_candidates_score_as_their_lines(allegro):
    job = ScoreJob.from_file(ALLEGRO, metrics='basic', backend='daqp')
    docs = [{'friction': {'mu_tangential': 0.6}},
            {'id': 'b', 'load': {'external_wrench': [0, 0, 1, 0, 0, 0]}}]
    from_lines = score_batch(job, [(i, json.dumps(d)) for i, d in enumerate(docs, 1)],
                             engine='serial')
    from_dicts = score_batch(job, docs, engine='serial')
    for a, b in zip(from_lines, from_dicts):
        assert a['line'] == b['line'] and a['id'] == b['id'] and a['status'] == b['status']
        assert a['torque_norm'] == pytest.approx(b['torque_norm'], rel=1e-9)
    assert docs[0] == {'friction': {'mu_tangential': 0.6}}  # not modified
    (setup_record,) = score_batch(job, [allegro], engine='serial')
    assert setup_record['line'] == 1 and setup_record['status'] == 'optimal'
    assert setup_record['torque_norm'] == pytest.approx(solve(allegro).torque_norm, rel=1e-6)


def test_records_carry_tau_and_wrenches_on_request(allegro):
    plain = score_batch(ScoreJob.from_file(ALLEGRO, metrics='basic'), [{}], engine='serial')[0]
    assert 'tau' not in plain and 'wrenches' not in plain
    job = ScoreJob.from_file(ALLEGRO, metrics='basic', solutions=True)
    (r,) = score_batch(job, [{}], engine='serial')
    maps = allegro.maps()
    tau, f = np.array(r['tau']), np.array(r['wrenches'])
    assert tau.shape == (allegro.hand.m,) and f.shape == (len(allegro.contacts), 4)
    assert_holds(allegro, maps, tau, f)
    assert np.linalg.norm(tau) == pytest.approx(r['torque_norm'])


def test_single_threaded_math_is_exported():
    import grasp_torque_opt

    assert 'single_threaded_math' in grasp_torque_opt.__all__
    grasp_torque_opt.single_threaded_math()


SCRIPT = (
    'from grasp_torque_opt import ScoreJob, score_batch\n'
    'job = ScoreJob.from_file({scenario!r}, metrics="basic")\n'
    'print(len(score_batch(job, [{{}}, {{}}, {{}}], workers=2, chunk=1)))\n'
)


def test_a_script_without_the_main_guard_raises_instead_of_hanging(tmp_path):
    path = tmp_path / 'no_guard.py'
    path.write_text(SCRIPT.format(scenario=str(ALLEGRO)))
    done = subprocess.run([sys.executable, str(path)], capture_output=True, text=True,
                          timeout=240, cwd=tmp_path)
    assert done.returncode != 0
    assert 'BrokenProcessPool' in done.stderr
    assert 'if __name__ == "__main__":' in done.stderr.splitlines()[-1]


def test_the_same_script_with_the_guard_scores(tmp_path):
    path = tmp_path / 'guarded.py'
    body = SCRIPT.format(scenario=str(ALLEGRO)).strip().splitlines()
    path.write_text('\n'.join(body[:1] + ['if __name__ == "__main__":']
                              + ['    ' + line for line in body[1:]]) + '\n')
    done = subprocess.run([sys.executable, str(path)], capture_output=True, text=True,
                          timeout=240, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == '3'
