# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The exit-code table every console script uses (docs/design.md section 4.2)."""

import subprocess
import sys

from grasp_torque_opt.core.command_line import (
    EXIT_BAD_INPUT,
    EXIT_FAILED,
    EXIT_INTERRUPTED,
    EXIT_OK,
    run_command,
)
from grasp_torque_opt.core.exceptions import InputError, SolverError
import pytest


def _raise(error: BaseException):
    def body() -> int:
        raise error
    return body


@pytest.mark.parametrize('error, code, line', [
    (InputError('friction.mu', 'must be > 0'), EXIT_BAD_INPUT,
     'prog: error: s.yaml: friction.mu: must be > 0'),
    (MemoryError(), EXIT_BAD_INPUT, 'prog: error: s.yaml: scenario: too large to process '
                                    '(MemoryError)'),
    (RecursionError(), EXIT_BAD_INPUT, 'prog: error: s.yaml: scenario: too large to process '
                                       '(RecursionError)'),
    (SolverError('no answer'), EXIT_FAILED, 'prog: error: no answer'),
    (FileNotFoundError(2, 'No such file or directory', 'out.jsonl'), EXIT_FAILED,
     'prog: error: out.jsonl: No such file or directory'),
])
def test_each_error_has_its_code_and_one_line(capsys, error, code, line):
    assert run_command('prog', _raise(error), lambda: 's.yaml') == code
    assert capsys.readouterr().err == line + '\n'


def test_a_line_stays_one_line_whatever_the_input_quotes(capsys):
    run_command('prog', _raise(InputError('grasp.contacts[0].link', 'a\nb\u2028c')))
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and '\\n' in err and '\\u2028' in err


def test_ctrl_c_exits_130_quietly(capsys):
    assert run_command('prog', _raise(KeyboardInterrupt())) == EXIT_INTERRUPTED
    assert capsys.readouterr().err == ''


def test_anything_else_is_a_bug_and_keeps_its_traceback():
    with pytest.raises(ZeroDivisionError):
        run_command('prog', _raise(ZeroDivisionError()))
    assert run_command('prog', lambda: EXIT_OK) == EXIT_OK


def test_score_answers_a_missing_base_scenario_with_one_line(tmp_path):
    lines = tmp_path / 'c.jsonl'
    lines.write_text('{}\n')
    done = subprocess.run([sys.executable, '-m', 'grasp_torque_opt.cli', 'score', str(lines),
                           '--scenario', str(tmp_path / 'missing.yaml'), '--workers', '1'],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == EXIT_BAD_INPUT and 'Traceback' not in done.stderr
    assert done.stderr.startswith(f'grasp-torque-opt: error: {tmp_path / "missing.yaml"}:')
