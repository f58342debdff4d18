# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The command line as a new user meets it: help, versions, errors that guide, safe inputs."""

from importlib import metadata
import json
from pathlib import Path
import subprocess
import sys

import box_grasp
from conftest import ALLEGRO, PLANAR
import pytest
import yaml


def cli(*args, timeout=120, cwd=None):
    """Run ``grasp-torque-opt`` as a process; return (exit code, stdout, stderr)."""
    done = subprocess.run([sys.executable, '-m', 'grasp_torque_opt.cli', *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, cwd=cwd)
    return done.returncode, done.stdout, done.stderr


def test_an_outward_normal_exits_2_naming_the_contact(tmp_path):
    doc = yaml.safe_load(PLANAR.read_text())
    doc['hand']['urdf'] = str(PLANAR.parent / doc['hand']['urdf'])
    doc['grasp']['contacts'][1]['normal'] = [0.998130, -0.061128, 0.0]  # flipped
    path = tmp_path / 'outward.yaml'
    path.write_text(yaml.safe_dump(doc))
    code, out, err = cli('solve', path, '--json')
    assert code == 2 and out == ''
    assert err.startswith(f'grasp-torque-opt: error: {path}: grasp.contacts[1].normal: the '
                          "normal of the contact on 'finger2_tip' points away from "
                          'grasp.object_origin')
    assert len(err.strip().splitlines()) == 1


def test_why_infeasible_names_friction_when_zero_load_cannot_be_held(tmp_path):
    code, out, err = cli('solve', box_grasp.write(tmp_path, box_grasp.scenario()), '--json')
    assert code == 3, err
    why = json.loads(out)['infeasibility']
    assert why['status'] == 'infeasible' and why['certified'] is True
    kinds = {c['constraint'] for c in why['binding']['contacts']}
    assert kinds == {'friction cone', 'min normal force'}
    assert why['binding']['joints'] == []
    assert why['relaxed'] == {'torque_limits': False, 'friction': True,
                              'min_normal_force': True}
    assert 'friction cones of' in why['text']
    code, out, _ = cli('solve', box_grasp.write(tmp_path, box_grasp.scenario(mu=1.0)), '--json')
    assert code == 0 and json.loads(out)['status'] == 'optimal'


@pytest.mark.parametrize('flip', ['thumb_tip'])
def test_a_flipped_box_normal_exits_2(tmp_path, flip):
    code, _, err = cli('solve', box_grasp.write(tmp_path, box_grasp.scenario(flip=flip)))
    assert code == 2 and f"contact on '{flip}'" in err


SCRIPTS = ['grasp-torque-opt', 'grasp-torque-sim', 'grasp-torque-demo']


def script(name, *args, timeout=120, cwd=None):
    """Run an installed console script of this venv."""
    exe = str(Path(sys.executable).parent / name)
    done = subprocess.run([exe, *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, cwd=cwd)
    return done.returncode, done.stdout, done.stderr


@pytest.mark.parametrize('command', [['grasp-torque-opt'], ['grasp-torque-opt', 'solve'],
                                     ['grasp-torque-opt', 'compare'],
                                     ['grasp-torque-opt', 'score'], ['grasp-torque-sim'],
                                     ['grasp-torque-demo']])
def test_every_console_script_says_what_it_does_and_its_defaults(command):
    code, out, _ = script(*command, '--help')
    assert code == 0
    _, _, rest = out.partition('\n\n')
    description = rest.split('\n\n')[0]
    assert len(description.split()) >= 10, description  # a sentence, not a name
    assert 'exit codes:' in out
    if command[1:] not in ([], ['compare']):  # those have no option with a default
        assert '(default: ' in out


@pytest.mark.parametrize('name', SCRIPTS)
def test_every_console_script_has_a_version(name):
    code, out, _ = script(name, '--version')
    assert code == 0
    assert out.split()[:2] == [name, metadata.version('grasp_torque_opt')]


@pytest.mark.parametrize('argv', [['--help'], ['-h', 'plan'], ['--help', 'solve']])
def test_the_top_level_help_gives_every_subcommands_line(argv):
    code, out, _ = script('grasp-torque-opt', *argv)
    text = ' '.join(out.split())
    assert code == 0 and 'exit codes:' in out
    for line in ('every method side by side', 'candidate grasps of an object',
                 "write the node's params file"):
        assert line in text, line


def test_solve_method_has_help():
    _, out, _ = cli('solve', '--help')
    assert 'force-qp: the QP over contact forces' in ' '.join(out.split())


def test_yaml_errors_say_line_and_column(tmp_path):
    path = tmp_path / 'broken.yaml'
    path.write_text('hand:\n  urdf: x.urdf\ngrasp:\n  contacts: [ {link: a\nfriction: {}\n')
    code, _, err = cli('solve', path)
    assert code == 2
    assert err.strip() == (f'grasp-torque-opt: error: {path}: scenario: {path} is not valid '
                           "YAML: line 5, column 9: expected ',' or '}', but got ':' (while "
                           'parsing a flow mapping at line 4, column 15)')


def test_an_unknown_link_gets_the_closest_links_first(tmp_path):
    doc = yaml.safe_load(ALLEGRO.read_text())
    doc['grasp']['contacts'][0]['link'] = 'link_3_tip'
    path = tmp_path / 'typo.yaml'
    path.write_text(yaml.safe_dump(doc))
    code, _, err = cli('solve', path)
    assert code == 2
    assert ("grasp.contacts[0].link: unknown frame 'link_3_tip' (did you mean 'link_3.0_tip' "
            'or ') in err
    listed = err.split('model frames: ')[1]
    assert listed.startswith('link_0.0, link_1.0, link_2.0, link_3.0, link_3.0_tip,')
    assert 'joint_' not in listed  # the links come first, the joint frames after


def test_an_unknown_joint_gets_the_closest_joint(tmp_path):
    doc = yaml.safe_load(ALLEGRO.read_text())
    doc['hand']['joints'][0] = 'joint_0'
    path = tmp_path / 'typo.yaml'
    path.write_text(yaml.safe_dump(doc))
    _, _, err = cli('solve', path)
    assert "unknown joint 'joint_0' (did you mean 'joint_0.0' or" in err


@pytest.mark.parametrize('command', ['solve', 'compare'])
def test_bundled_scenario_names_are_accepted(tmp_path, command):
    code, out, err = cli(command, 'planar_two_finger.yaml', '--json', cwd=tmp_path)
    assert code == 0, err
    assert json.loads(out)


def test_score_takes_a_bundled_base_and_says_what_it_ranks_by(tmp_path):
    candidates = tmp_path / 'c.jsonl'
    candidates.write_text('{"id": "a"}\n{"id": "b", "friction": {"mu_tangential": 0.8}}\n')
    code, out, err = cli('score', candidates, '--scenario', 'planar_two_finger.yaml',
                         '--metrics', 'basic', '--engine', 'serial', cwd=tmp_path)
    assert code == 0, err
    assert '(ranked by torque_norm)' in out and 'capacity' not in out
    code, out, err = cli('score', candidates, '--scenario', 'planar_two_finger.yaml',
                         '--engine', 'serial', cwd=tmp_path)
    assert code == 0, err
    assert '(ranked by capacity)' in out


def test_score_draws_its_progress_bar_with_tqdm_on_a_terminal(tmp_path):
    import os
    import pty

    candidates = tmp_path / 'c.jsonl'
    candidates.write_text('{"id": "a"}\n{"id": "b"}\n')
    main_fd, tty = pty.openpty()
    try:
        done = subprocess.run([sys.executable, '-m', 'grasp_torque_opt.cli', 'score',
                               str(candidates), '--scenario', 'planar_two_finger.yaml',
                               '--metrics', 'basic', '--engine', 'serial'],
                              stdout=subprocess.PIPE, stderr=tty, text=True, timeout=120,
                              cwd=tmp_path)
        os.close(tty)
        err = b''
        while True:
            try:
                chunk = os.read(main_fd, 4096)
            except OSError:
                break
            if not chunk:
                break
            err += chunk
    finally:
        os.close(main_fd)
    assert done.returncode == 0
    assert b'scoring: 100%' in err and b'2/2' in err


def test_score_records_carry_the_solutions_on_request(tmp_path):
    candidates = tmp_path / 'c.jsonl'
    candidates.write_text('{"id": "a"}\n')
    code, out, err = cli('score', candidates, '--scenario', 'planar_two_finger.yaml',
                         '--metrics', 'basic', '--engine', 'serial', '--json', '--solutions',
                         cwd=tmp_path)
    assert code == 0, err
    (record,) = [json.loads(line) for line in out.splitlines()]
    assert len(record['tau']) == 4 and len(record['wrenches']) == 2


def test_a_plan_imports_no_scipy(tmp_path):
    """
    The planner's start-up (issue 36): ``plan`` runs without importing SciPy.

    Its IK solver is the package's own, SciPy's LP and LAPACK are imported where they
    are first used, and a zero load DAQP does not hold drops a candidate without HiGHS's
    confirmation (``load_capacity(..., confirm=False)``): SciPy's imports were 0.4 s of
    a 0.8 s start-up, and 0.3 s more at the first such candidate. The plan below has
    some (its summary says so).
    """
    code = ('import sys; from grasp_torque_opt.cli import main; sys.argv[1:] = '
            f"['plan', 'allegro_right.yaml', '--count', '20', '--out', {str(tmp_path / 'p')!r}]"
            '\ntry:\n    main()\nexcept SystemExit as e:\n    assert not e.code, e.code\n'
            "print(sorted(m for m in sys.modules if m.split('.')[0] == 'scipy'))")
    done = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                          timeout=120, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == '[]', done.stdout
    assert (tmp_path / 'p').read_text().count('\n') == 20
    assert 'infeasible for its load' in done.stderr, done.stderr
