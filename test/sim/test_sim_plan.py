# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The planner's loop from the package's commands: plan, score, ``grasp-torque-sim --plan``.

Each step is the console command a user runs (``python -m`` on this tree), on the
bundled Allegro and its ball, in simulated time.
"""

import json
import os
import subprocess
import sys

from conftest import ROOT
from PIL import Image
import pytest


def command(*args, module='grasp_torque_opt.ros.sim_driver', timeout=180):
    env = dict(os.environ)
    env.pop('MUJOCO_GL', None)  # as a user starts it
    return subprocess.run([sys.executable, '-m', module, *args], capture_output=True,
                          text=True, timeout=timeout, cwd=ROOT, env=env)


@pytest.fixture(scope='module')
def loop(tmp_path_factory):
    """Plan 4 candidates and score them with the package's commands; return the files."""
    folder = tmp_path_factory.mktemp('loop')
    plan, scores = folder / 'plan.jsonl', folder / 'scores.jsonl'
    done = command('plan', 'allegro_right.yaml', '--count', '4', '--seed', '0', '--out',
                   str(plan), module='grasp_torque_opt.cli')
    assert done.returncode == 0, done.stderr
    done = command('score', str(plan), '--scenario', 'allegro_right.yaml', '--out',
                   str(scores), '--workers', '1', module='grasp_torque_opt.cli')
    assert done.returncode == 0, done.stderr
    records = [json.loads(t) for t in scores.read_text().splitlines()]
    lines = [json.loads(t) for t in plan.read_text().splitlines()]
    return folder, plan, scores, lines, records


def best_line(stdout: str) -> str:
    lines = [t for t in stdout.splitlines() if t.startswith('best: ')]
    assert len(lines) == 1, stdout
    return lines[0]


def test_the_loop_simulates_the_candidate_of_the_largest_capacity(loop):
    folder, plan, scores, lines, records = loop
    feasible = [r for r in records if r['status'] == 'optimal']
    assert len(feasible) >= 2, records
    # Independently of the ranking code: score ranks by capacity, the largest first.
    want = max(feasible, key=lambda r: r['capacity'])
    picture = folder / 'best.png'
    done = command('--plan', str(plan), '--scores', str(scores), '--duration', '1',
                   '--picture', str(picture))
    said = best_line(done.stdout)
    assert done.returncode == 0 and said.startswith(f"best: {want['id']} (rank 1 of "), \
        done.stdout + done.stderr
    assert "with the node's torques: held" in said and str(picture) in said
    with Image.open(picture) as image:
        assert image.size[0] >= 800


def test_it_simulates_the_best_ranked_line_and_not_another(loop, tmp_path):
    """The rank-1 line made 30 times heavier: that ball falls, so that line was simulated."""
    _, plan, scores, lines, records = loop
    feasible = sorted((r for r in records if r['status'] == 'optimal'), key=lambda r: r['rank'])
    second = feasible[1]
    # The second-best becomes rank 1 (the ranks swapped) and its ball 30 times heavier.
    swapped = []
    for r in records:
        r = dict(r)
        if r['id'] == second['id']:
            r['rank'] = 1
        elif r['rank'] == 1:
            r['rank'] = second['rank']
        swapped.append(json.dumps(r))
    heavy = []
    for line in lines:
        if line['id'] == second['id']:
            line = dict(line, object=dict(line['object'], mass=30 * line['object']['mass']))
        heavy.append(json.dumps(line))
    (tmp_path / 'plan.jsonl').write_text('\n'.join(heavy) + '\n')
    (tmp_path / 'scores.jsonl').write_text('\n'.join(swapped) + '\n')
    done = command('--plan', str(tmp_path / 'plan.jsonl'), '--scores',
                   str(tmp_path / 'scores.jsonl'), '--duration', '1', '--no-picture')
    said = best_line(done.stdout)
    assert done.returncode == 1 and said.startswith(f"best: {second['id']} (rank 1 "), said
    assert "with the node's torques: NOT held" in said


@pytest.mark.parametrize('change, message', [
    ('no scores', '--plan and --scores: give both'),
    ('with node', "--plan: the node's own cycle simulates the candidate, without ROS"),
    ('none feasible', '--scores: '),
    ('other plan', 'is not the candidate'),
    ('not json', 'line 1 is not valid JSON'),
])
def test_bad_loop_input_gives_one_line_and_exit_2(loop, tmp_path, change, message):
    _, plan, scores, lines, records = loop
    args = ['--plan', str(plan), '--scores', str(scores), '--no-picture']
    if change == 'no scores':
        args = args[:2]
    elif change == 'with node':
        args.append('--with-node')
    elif change == 'none feasible':
        bad = tmp_path / 'scores.jsonl'
        bad.write_text(''.join(json.dumps(dict(r, status='infeasible')) + '\n'
                               for r in records))
        args[3] = str(bad)
    elif change == 'other plan':
        bad = tmp_path / 'plan.jsonl'
        bad.write_text(''.join(json.dumps(dict(line, id='x' + line['id'])) + '\n'
                               for line in lines))
        args[1] = str(bad)
    else:
        bad = tmp_path / 'plan.jsonl'
        bad.write_text('{not json\n')
        args[1] = str(bad)
    done = command(*args, timeout=60)
    assert done.returncode == 2 and done.stdout == '', done.stdout + done.stderr
    assert len(done.stderr.splitlines()) == 1 and message in done.stderr, done.stderr
    assert done.stderr.startswith('grasp-torque-sim: error: ')
