# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The command line: its JSON contract, exit codes and one-line errors."""

import json
import re
import subprocess
import sys

from bad_scenarios import BAD, mutated
from conftest import ALLEGRO, PLANAR
from grasp_torque_opt.cli import main
from independent import assert_holds
import numpy as np
import pytest
import yaml

PINNED = {'status', 'method', 'joints', 'tau', 'torque_norm', 'solve_time_s', 'certificate',
          'contacts'}


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize('method', ['tau-qp', 'force-qp', 'socp'])
def test_solve_json_contract(planar, capsys, method):
    code, out, err = run(['solve', str(PLANAR), '--method', method, '--json'], capsys)
    assert code == 0 and err == ''
    d = json.loads(out)
    assert PINNED <= set(d)
    assert d['status'] == 'optimal' and d['method'] == method
    assert d['joints'] == planar.hand.joints
    assert d['torque_norm'] == pytest.approx(np.linalg.norm(d['tau']))
    assert d['certificate']['ok'] is True
    assert [c['link'] for c in d['contacts']] == [c.link for c in planar.contacts]
    wrenches = np.array([c['wrench'] for c in d['contacts']])
    assert_holds(planar, planar.maps(), np.array(d['tau']), wrenches)
    for c in d['contacts']:
        R = np.column_stack((c['tangent'], np.cross(c['normal'], c['tangent']), c['normal']))
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)


def test_infeasible_exits_3_without_torques(tmp_path, capsys):
    doc = yaml.safe_load(PLANAR.read_text())
    doc['load']['external_wrench'] = [0.0, -500.0, 0.0, 0.0, 0.0, 0.0]
    doc['hand']['urdf'] = str(PLANAR.parent / doc['hand']['urdf'])
    path = tmp_path / 'heavy.yaml'
    path.write_text(yaml.safe_dump(doc))
    code, out, _ = run(['solve', str(path), '--json'], capsys)
    d = json.loads(out)
    assert code == 3 and d['status'] == 'infeasible'
    assert d['tau'] is None and all(c['wrench'] is None for c in d['contacts'])


@pytest.mark.parametrize('path,value,field,problem', BAD,
                         ids=['.'.join(map(str, b[0])) + f'={b[1]!r}' for b in BAD])
def test_bad_scenario_file_exits_2_with_one_line(tmp_path, capsys, planar_doc, path, value,
                                                 field, problem):
    doc = mutated(planar_doc, path, value)
    if 'urdf' in doc['hand']:
        doc['hand']['urdf'] = str(PLANAR.parent / doc['hand']['urdf'])
    bad = tmp_path / 'bad.yaml'
    bad.write_text(yaml.dump(doc))
    code, out, err = run(['solve', str(bad), '--json'], capsys)
    assert code == 2 and out == ''
    assert len(err.splitlines()) == 1
    assert re.match(rf'grasp-torque-opt: error: {re.escape(str(bad))}: {field}: ', err), err
    assert re.search(problem, err)


def test_compare_table_and_json(capsys):
    code, out, _ = run(['compare', str(PLANAR)], capsys)
    assert code == 0
    for label in ('tau-QP (ours)', 'force QP', 'exact SOCP', 'exact NLP', '||tau||_2',
                  'joint4', 'Excess of the tau-QP over the exact-cone optimum'):
        assert label in out
    code, out, _ = run(['compare', str(PLANAR), '--json'], capsys)
    d = json.loads(out)
    assert set(d['methods']) == {'tau-qp', 'tau-qp-adaptive', 'force-qp', 'socp', 'nlp'}
    norms = {m: s['torque_norm'] for m, s in d['methods'].items()}
    assert d['excess_over_exact'] == pytest.approx(norms['tau-qp'] / norms['socp'] - 1)
    assert d['reduction_vs']['force-qp'] == pytest.approx(1 - norms['tau-qp'] / norms['force-qp'])
    # The tau-QP minimizes torques over the same polygon as the force QP: never worse.
    assert d['reduction_vs']['force-qp'] >= -1e-6


def test_console_script_runs_as_installed():
    exe = [sys.executable, '-m', 'grasp_torque_opt.cli']
    done = subprocess.run(exe + ['solve', str(ALLEGRO), '--json'], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)['status'] == 'optimal'
    done = subprocess.run(exe + ['solve', '/nonexistent.yaml'], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 2
    assert done.stderr.strip().startswith('grasp-torque-opt: error: /nonexistent.yaml: scenario:')


@pytest.mark.parametrize('path,value', [(('hand', 'torque_limits'), [10.0, 5.0, 10.0, 5.0]),
                                        (('objective',), {'weights': [1.0, 2.0, 1.0, 2.0]})])
def test_per_joint_lists_without_joints_exit_2(tmp_path, capsys, planar_doc, path, value):
    """
    Per-joint values need hand.joints: without it they would follow Pinocchio's joint order.

    That order is not the URDF file's (the Allegro's model order is 0-3, 12-15, 4-7, 8-11).
    """
    doc = mutated(mutated(planar_doc, ('hand', 'joints'), None), path, value)
    doc['hand']['urdf'] = str(PLANAR.parent / doc['hand']['urdf'])
    bad = tmp_path / 'bad.yaml'
    bad.write_text(yaml.dump(doc))
    code, out, err = run(['solve', str(bad)], capsys)
    assert code == 2 and out == ''
    assert re.search(r': hand.joints: required when (hand.torque_limits|objective.weights) '
                     r'gives one value per joint', err), err
    # A single limit for every joint needs no order.
    doc['hand']['torque_limits'] = 5.0
    doc.pop('objective', None)
    bad.write_text(yaml.dump(doc))
    assert run(['solve', str(bad)], capsys)[0] == 0


@pytest.mark.parametrize('backend', ['daqp', 'quadprog'])
def test_backend_option_gives_the_same_certified_torques(allegro, capsys, backend):
    code, out, _ = run(['solve', str(ALLEGRO), '--json'], capsys)
    default = json.loads(out)
    code, out, err = run(['solve', str(ALLEGRO), '--backend', backend, '--json'], capsys)
    assert code == 0 and err == ''
    d = json.loads(out)
    assert d['certificate']['ok'] is True and backend.upper()[:4] in d['message'].upper()
    np.testing.assert_allclose(d['tau'], default['tau'], atol=1e-6)


def test_fallback_answers_for_a_backend_that_cannot(planar, capsys):
    """Quadprog cannot take the planar grasp's internal force: DAQP answers, unless told not to."""
    code, out, _ = run(['solve', str(PLANAR), '--backend', 'quadprog', '--json'], capsys)
    d = json.loads(out)
    assert code == 0 and d['certificate']['ok'] is True
    assert 'fallback after quadprog' in d['message']
    code, out, _ = run(['solve', str(PLANAR), '--backend', 'quadprog', '--fallback', 'none',
                        '--json'], capsys)
    assert code == 4 and json.loads(out)['tau'] is None


@pytest.mark.parametrize('urdf', ['a\nb.urdf', '\x85', 'x\u2028y.urdf', 'tab\there.urdf'])
def test_line_breaks_in_the_input_stay_escaped_in_the_one_line(tmp_path, capsys, planar_doc,
                                                               urdf):
    r"""str.splitlines() breaks at \\x85 and \\u2028 too: the quoted input must not."""
    doc = mutated(planar_doc, ('hand', 'urdf'), urdf)
    bad = tmp_path / 'bad.yaml'
    bad.write_text(yaml.safe_dump(doc))
    code, out, err = run(['solve', str(bad), '--json'], capsys)
    assert code == 2 and out == ''
    assert len(err.splitlines()) == 1 and err.endswith('\n')
    assert err.startswith(f'grasp-torque-opt: error: {bad}: hand.urdf: file not found: ')
    assert urdf.encode('unicode_escape').decode('ascii') in err


def test_a_reader_that_goes_away_gets_no_traceback():
    """`grasp-torque-opt solve ... | head -1`: the pipe closes before the output is written."""
    child = subprocess.Popen([sys.executable, '-m', 'grasp_torque_opt.cli', 'solve', str(ALLEGRO)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    child.stdout.close()  # the reader is gone before the solve has printed anything
    err = child.stderr.read().decode()
    assert child.wait(timeout=120) in (0, 141)
    assert 'Traceback' not in err, err
