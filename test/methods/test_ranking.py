# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Ranking: feasible by the key, then infeasible by holdable fraction, then the rest."""

import json
import math

from conftest import ALLEGRO
from grasp_torque_opt.methods.engines import score_batch
from grasp_torque_opt.methods.ranking import format_table, rank, rank_group
from grasp_torque_opt.methods.score import ScoreJob
from independent import lp_capacity
import pytest


def record(line, status, capacity=None, fraction=None, norm=None):
    """Return a scored record with only what the ranking reads."""
    return {'line': line, 'id': f'c{line}', 'status': status, 'capacity': capacity,
            'holdable_fraction': fraction, 'torque_norm': norm, 'capacities': {}}


RECORDS = [
    record(1, 'error'),
    record(2, 'infeasible', 0.3, 0.3),
    record(3, 'optimal', 2.0, norm=0.3),
    record(4, 'failed'),
    record(5, 'infeasible', 0.0, 0.0),  # cannot hold zero load: fraction 0, still ranked
    record(6, 'optimal', 5.0, norm=0.5),
    record(7, 'infeasible'),  # no fraction: with the rest
    record(8, 'infeasible', 0.7, 0.7),
    record(9, 'optimal', None, norm=0.1),  # no capacity: after those with one
    record(10, 'optimal', 0.0, norm=0.2),  # holds its load, not zero load
]


def test_the_groups_come_in_order_each_sorted_by_its_own_key():
    lines = [r['line'] for r in rank(RECORDS, 'capacity')]
    # Written out: feasible by capacity (largest first, none last), infeasible by
    # fraction (largest first), then infeasible without one, failed, bad.
    assert lines == [6, 3, 10, 9, 8, 2, 5, 7, 4, 1]
    assert [r['line'] for r in rank(RECORDS, 'torque_norm')][:4] == [9, 10, 3, 6]
    assert [rank_group(r) for r in rank(RECORDS)] == \
        ['feasible'] * 4 + ['infeasible'] * 3 + ['rest'] * 3


def test_the_table_names_each_rows_group():
    rows = format_table(rank(RECORDS), top=len(RECORDS)).splitlines()
    assert rows[0].split()[:3] == ['rank', 'group', 'line']
    assert [row.split()[1] for row in rows[1:]] == \
        ['feasible'] * 4 + ['infeasible'] * 3 + ['rest'] * 3


@pytest.fixture(scope='module')
def scored():
    """Allegro lines: two held, three infeasible (heavier balls, a squeeze too hard), a bad one."""
    lines = [{'id': 'as-is'}, {'id': 'x3', 'object': {'mass': 0.45}},
             {'id': 'x20', 'object': {'mass': 3.0}}, {'id': 'x10', 'object': {'mass': 1.5}},
             {'id': 'squeeze', 'friction': {'min_normal_force': 50.0}},
             {'id': 'bad', 'grasp': {'contacts': []}}]
    job = ScoreJob.from_file(ALLEGRO)
    return score_batch(job, [(i, json.dumps(c)) for i, c in enumerate(lines, 1)],
                       engine='serial')


def test_score_batch_records_carry_their_rank(scored, allegro):
    by_id = {r['id']: r for r in scored}
    order = sorted(scored, key=lambda r: r['rank'])
    assert [r['rank'] for r in order] == list(range(1, len(scored) + 1))
    assert [r['id'] for r in order] == ['as-is', 'x3', 'x10', 'x20', 'squeeze', None]
    # The fractions that order the infeasible ones: HiGHS's largest multiple, 1/10 and
    # 1/20 of the bundled grasp's capacity (the load is the ball's weight).
    maps = allegro.maps()
    alpha, _ = lp_capacity(allegro, maps, allegro.external_wrench)
    for ident, times in (('x10', 10), ('x20', 20)):
        assert by_id[ident]['status'] == 'infeasible'
        assert by_id[ident]['holdable_fraction'] == pytest.approx(alpha / times, rel=1e-6)
    squeeze = by_id['squeeze']
    assert squeeze['holdable_fraction'] == 0.0 and rank_group(squeeze) == 'infeasible'
    assert 'not even zero load' in squeeze['capacity_reason']
    bad = order[-1]
    assert (bad['line'], bad['status'], rank_group(bad)) == (6, 'error', 'rest')


def test_an_infeasible_candidate_always_has_a_fraction_or_a_reason(scored):
    for r in scored:
        if r['status'] == 'infeasible':
            v = r['holdable_fraction']
            assert (v is not None and math.isfinite(v) and 0 <= v < 1) or r['capacity_reason']


def test_an_unknown_rank_key_fails_before_scoring():
    with pytest.raises(ValueError, match='rank key must be one of'):
        score_batch(ScoreJob.from_file(ALLEGRO), [{'id': 'a'}], rank_by='effort')
