# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The command line with tau-qp-adaptive: its bounds in the JSON (new keys), its flags."""

import json

from conftest import ALLEGRO, PLANAR
from grasp_torque_opt.cli import main
from grasp_torque_opt.methods.dispatch import solve
from independent import assert_holds
import numpy as np
import pytest

PINNED = {'status', 'method', 'joints', 'tau', 'torque_norm', 'solve_time_s', 'certificate',
          'contacts'}
BOUNDS = {'lower', 'upper', 'gap', 'tolerance', 'converged', 'rounds', 'qp_solves', 'source'}


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize('path,fixture', [(PLANAR, 'planar'), (ALLEGRO, 'allegro')])
def test_solve_json_has_the_pinned_keys_and_the_bounds(path, fixture, capsys, request):
    setup = request.getfixturevalue(fixture)
    code, out, err = run(['solve', str(path), '--method', 'tau-qp-adaptive', '--json'], capsys)
    assert code == 0 and err == ''
    d = json.loads(out)
    assert PINNED <= set(d) and d['method'] == 'tau-qp-adaptive'
    wrenches = np.array([c['wrench'] for c in d['contacts']])
    assert_holds(setup, setup.maps(), np.array(d['tau']), wrenches)
    b = d['bounds']
    assert set(b) == BOUNDS and b['converged'] and b['gap'] <= 1e-3
    exact = solve(setup, 'socp').torque_norm  # W = I in both scenarios
    assert b['lower'] <= exact * (1 + 1e-8) and b['upper'] >= exact * (1 - 1e-8)
    assert b['upper'] == pytest.approx(d['torque_norm'])


def test_other_methods_have_null_bounds(capsys):
    code, out, _ = run(['solve', str(PLANAR), '--json'], capsys)
    assert code == 0 and json.loads(out)['bounds'] is None


def test_flags_and_the_text_output(capsys):
    code, out, _ = run(['solve', str(PLANAR), '--method', 'tau-qp-adaptive', '--max-rounds',
                        '0'], capsys)
    assert code == 0
    assert 'bounds on the exact optimum' in out and '0 rounds' in out
    code, out, _ = run(['solve', str(PLANAR), '--method', 'tau-qp-adaptive', '--gap', '0.5',
                        '--json'], capsys)
    assert code == 0 and json.loads(out)['bounds']['tolerance'] == 0.5


@pytest.mark.parametrize('flag,value', [('--gap', 'nan'), ('--gap', '0'), ('--gap', '-1'),
                                        ('--max-rounds', '-1'), ('--max-rounds', 'x')])
def test_bad_flags_are_usage_errors(flag, value, capsys):
    with pytest.raises(SystemExit) as e:
        main(['solve', str(PLANAR), '--method', 'tau-qp-adaptive', flag, value])
    assert e.value.code == 2
    assert flag in capsys.readouterr().err


def test_compare_json_and_table_carry_the_adaptive_method(capsys):
    code, out, _ = run(['compare', str(PLANAR), '--json'], capsys)
    d = json.loads(out)
    ada, exact = d['methods']['tau-qp-adaptive'], d['methods']['socp']
    assert ada['bounds']['lower'] <= exact['torque_norm'] * (1 + 1e-8)
    assert d['adaptive_excess_over_exact'] == pytest.approx(
        ada['torque_norm'] / exact['torque_norm'] - 1)
    assert abs(d['adaptive_excess_over_exact']) < 1e-3 < d['excess_over_exact']
    code, out, _ = run(['compare', str(PLANAR)], capsys)
    assert 'tau-QP adaptive' in out and 'lower bound' in out and 'gap' in out
