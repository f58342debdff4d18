# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The batch stages read candidate lines with orjson: the standard library's answers.

Every line json reads the same is read the same; the lines orjson refuses (NaN, an
infinite number, deep nesting) go to the single path, which reads them with json as
before; an id beyond 64 bits is written back as given; and the records are the same
with orjson hidden.
"""

import json

from conftest import ALLEGRO
from grasp_torque_opt.control import compiled
from grasp_torque_opt.methods import batch
from grasp_torque_opt.methods.batch import BatchScorer
from grasp_torque_opt.methods.score import ScoreJob, Scorer
from grasp_torque_opt.native import loader
import pytest
from test_batch import assert_same, candidates

pytestmark = [pytest.mark.skipif(not compiled.available(), reason=loader.IMPORT_ERROR),
              pytest.mark.skipif(batch._orjson_loads is None, reason='orjson not installed')]

ODD = ['[NaN]', '{"id": 1, "load": {"external_wrench": [NaN, 0, 0, 0, 0, 0]}}',
       '{"id": 1e400}', '[' * 1100 + ']' * 1100, '{"id": 18446744073709551616}',
       '{"id": -9223372036854775809, "grasp": {}}', '{"a": 1, "a": 2}', '"\\ud800"']


def test_every_line_json_reads_is_read_the_same_or_refused():
    lines = [text for _, text in candidates(60, seed=7)] + ODD
    refused = 0
    for text in lines:
        try:
            expected = json.loads(text)
        except (ValueError, RecursionError):
            with pytest.raises(ValueError):
                batch.loads(text)
            continue
        try:
            got = batch.loads(text)
        except ValueError:
            refused += 1
            continue
        assert got == expected and type(got) is type(expected)
        if isinstance(got, dict) and 'id' in got:
            assert type(got['id']) is type(expected['id'])
    # json reads them, orjson does not: NaN twice, 1e400 (inf), the depth, a lone surrogate.
    assert refused == 5


def odd_candidates() -> list[tuple[int, str]]:
    """Good lines, and lines only json reads (a NaN load, an infinite id), a 70-bit id."""
    lines = candidates(20, seed=8)
    good = json.loads(lines[0][1])
    big = dict(good, id=2 ** 70)
    nan = dict(good, load={'external_wrench': [0.0] * 6})
    text = json.dumps(nan).replace('[0.0, 0.0', '[NaN, 0.0', 1)
    n = len(lines)
    return lines + [(n + 1, json.dumps(big)), (n + 2, text), (n + 3, '{"id": 1e400}')]


def test_the_records_are_the_single_paths_and_the_same_without_orjson(monkeypatch):
    job = ScoreJob.from_file(ALLEGRO, metrics='basic', solutions=True)
    lines = odd_candidates()
    fast = BatchScorer(Scorer(job)).score_lines(lines)
    assert_same(fast, Scorer(job).score_lines(lines), tol=1e-9)
    assert fast[-3]['id'] == 2 ** 70 and type(fast[-3]['id']) is int
    assert fast[-3]['status'] == 'optimal'
    assert fast[-2]['status'] == 'error'  # the NaN load, named by the single path
    # Without orjson json reads the infinite id and the batch stages score that line
    # (its answer the single path's to 1e-9, not to the last bit); the rest is the same.
    monkeypatch.setattr(batch, '_orjson_loads', None)
    assert_same(BatchScorer(Scorer(job)).score_lines(lines), fast, tol=1e-9)
