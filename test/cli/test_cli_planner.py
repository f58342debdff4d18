# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The planner's command line: --objective, --margin, --capacity, the infeasible explanation.

Also ``score`` on a generated batch: bad lines named, the rest scored, files written.
"""

import copy
import json
import subprocess
import sys

from conftest import ALLEGRO, ROOT
from grasp_torque_opt.cli import main
from independent import lp_capacity
import numpy as np
import pytest
import yaml


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_solve_json_has_the_planner_keys(capsys):
    code, out, _ = run(['solve', str(ALLEGRO), '--json', '--objective', 'min-max',
                        '--margin', '0.25'], capsys)
    d = json.loads(out)
    assert code == 0 and d['objective'] == 'min-max' and d['friction_margin'] == 0.25
    usage = [c['friction_usage'] for c in d['contacts']]
    assert max(usage) == d['friction_usage_max'] <= 1 / 1.25 + 1e-7
    lim = 0.7  # the bundled scenario's limit on every joint
    assert d['max_torque_ratio'] == pytest.approx(max(abs(t) for t in d['tau']) / lim)
    assert d['infeasibility'] is None and 'capacity' not in d


def test_solve_capacity(allegro, capsys):
    code, out, _ = run(['solve', str(ALLEGRO), '--json', '--capacity'], capsys)
    cap = json.loads(out)['capacity']
    maps = allegro.maps()
    alpha, _ = lp_capacity(allegro, maps, allegro.external_wrench)
    assert cap['load']['value'] == pytest.approx(alpha, rel=1e-6) and cap['load']['certified']
    assert len(cap['directions']) == 12 and cap['directions']['-Fz']['unit'] == 'N'
    d = np.zeros(6)
    d[2] = -1.0
    assert cap['directions']['-Fz']['value'] == pytest.approx(lp_capacity(allegro, maps, d)[0],
                                                              rel=1e-6)
    code, text, _ = run(['solve', str(ALLEGRO), '--capacity'], capsys)
    assert 'times the load' in text and '-Fz' in text


def test_an_infeasible_load_is_explained(tmp_path, allegro_doc, capsys):
    doc = copy.deepcopy(allegro_doc)
    doc['object']['mass'] = 1.5
    doc['hand']['urdf'] = allegro_doc['hand']['urdf']
    path = tmp_path / 'heavy.yaml'
    path.write_text(yaml.safe_dump(doc))
    code, out, _ = run(['solve', str(path), '--json'], capsys)
    d = json.loads(out)
    assert code == 3 and d['status'] == 'infeasible'
    why = d['infeasibility']
    assert 0 < why['holdable_fraction'] < 1 and why['certified']
    assert why['binding']['joints'] or why['binding']['contacts']
    code, text, _ = run(['solve', str(path)], capsys)
    assert code == 3 and 'why: at most' in text and '% of this load can be held' in text


@pytest.mark.parametrize('argv, fragment', [
    (['solve', str(ALLEGRO), '--margin', '-1'], '--margin'),
    (['solve', str(ALLEGRO), '--margin', 'nan'], '--margin'),
    (['solve', str(ALLEGRO), '--objective', 'max'], '--objective'),
    (['score', 'c.jsonl', '--scenario', str(ALLEGRO), '--workers', '0'], '--workers'),
    (['score', 'c.jsonl', '--scenario', str(ALLEGRO), '--workers', '100000'], '--workers'),
    (['score', 'c.jsonl', '--scenario', str(ALLEGRO), '--top', '-1'], '--top'),
    (['score', 'c.jsonl'], '--scenario'),
])
def test_bad_planner_flags_are_usage_errors(argv, fragment, capsys):
    with pytest.raises(SystemExit) as e:
        main(argv)
    assert e.value.code == 2 and fragment in capsys.readouterr().err


def test_score_on_a_generated_batch(tmp_path):
    """As a fresh clone would: generate candidates with bench/candidates.py, score them."""
    batch = tmp_path / 'candidates.jsonl'
    subprocess.run([sys.executable, str(ROOT / 'bench' / 'candidates.py'), '--count', '40',
                    '--bad', '20', '--out', str(batch)], check=True, timeout=60)
    out = tmp_path / 'scores.jsonl'
    done = subprocess.run([sys.executable, '-m', 'grasp_torque_opt.cli', 'score', str(batch),
                           '--scenario', str(ALLEGRO), '--out', str(out), '--workers', '2'],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2  # two bad lines: named on stderr, the rest scored
    errors = done.stderr.strip().splitlines()
    assert len(errors) == 2 and 'Traceback' not in done.stderr
    for line, error in zip((20, 40), errors):
        assert f'c{line - 1}' not in error and f': line {line}: grasp.contacts[0].link:' in error
    assert 'scored 40 candidates' in done.stdout and ' 2 error' in done.stdout
    records = [json.loads(x) for x in out.read_text().splitlines()]
    assert [r['line'] for r in records] == list(range(1, 41))
    assert sorted(r['rank'] for r in records) == list(range(1, 41))
    scored = [r for r in records if r['status'] != 'error']
    assert len(scored) == 38 and all(len(r['capacities']) == 12 for r in scored)


def test_score_json_and_bad_files(tmp_path, capsys):
    batch = tmp_path / 'c.jsonl'
    batch.write_text('{"id": 1}\n\n{"id": 2, "friction": {"margin": 0.5}}\n')
    code, out, err = run(['score', str(batch), '--scenario', str(ALLEGRO), '--json',
                          '--engine', 'serial', '--metrics', 'basic'], capsys)
    assert code == 0 and err == ''
    records = [json.loads(x) for x in out.splitlines()]
    assert [r['line'] for r in records] == [1, 3] and 'capacity' not in records[0]
    code, _, err = run(['score', str(tmp_path / 'none.jsonl'), '--scenario', str(ALLEGRO)],
                       capsys)
    assert code == 2 and err.count('\n') == 1 and 'candidates: cannot read' in err
    code, _, err = run(['score', str(batch), '--scenario', str(tmp_path / 'none.yaml')], capsys)
    assert code == 2 and 'scenario: file not found' in err


def test_the_progress_bar_is_drawn_on_a_terminal_only(tmp_path, capsys, monkeypatch):
    batch = tmp_path / 'c.jsonl'
    batch.write_text('{"id": 1}\n{"id": 2}\n')
    argv = ['score', str(batch), '--scenario', str(ALLEGRO), '--engine', 'serial',
            '--metrics', 'basic']
    assert run(argv, capsys)[2] == ''  # captured stderr is no terminal
    monkeypatch.setattr(sys.stderr, 'isatty', lambda: True, raising=False)
    code, _, err = run(argv, capsys)
    assert code == 0 and '\rscoring: 100%' in err and '2/2' in err
