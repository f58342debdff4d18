# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The command line as a new user meets it: help, versions, errors that guide, safe inputs."""

import json
import subprocess
import sys

import box_grasp
from conftest import PLANAR
import pytest
import yaml


def cli(*args, timeout=120):
    """Run ``grasp-torque-opt`` as a process; return (exit code, stdout, stderr)."""
    done = subprocess.run([sys.executable, '-m', 'grasp_torque_opt.cli', *map(str, args)],
                          capture_output=True, text=True, timeout=timeout)
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
    assert {c['constraint'] for c in why['binding']['contacts']} == {'friction cone',
                                                                      'min normal force'}
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
