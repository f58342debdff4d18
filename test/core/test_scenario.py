# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Scenario validation: each kind of bad input names its field."""

from pathlib import Path

from bad_scenarios import BAD, mutated
from conftest import CONFIG, setup_from_doc
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.scenario import load_scenario, parse_scenario
import pytest


@pytest.mark.parametrize('path,value,field,problem', BAD,
                         ids=['.'.join(map(str, b[0])) + f'={b[1]!r}' for b in BAD])
def test_bad_input_names_its_field(planar_doc, path, value, field, problem):
    with pytest.raises(InputError, match=rf'^{field}: .*{problem}|^{field}: {problem}'):
        setup_from_doc(mutated(planar_doc, path, value))


def test_default_normal_at_the_origin_is_refused(planar_doc):
    doc = mutated(planar_doc, ('grasp', 'contacts', 0, 'normal'), None)
    doc['grasp']['object_origin'] = [-0.0344682714, 0.1186824089, 0.0]  # finger1_tip itself
    doc['grasp']['contacts'][0]['position'] = [0.0, 0.0, 0.0]
    with pytest.raises(InputError, match=r'grasp.contacts\[0\].normal: cannot default'):
        setup_from_doc(doc)


def test_urdf_not_found(planar_doc):
    with pytest.raises(InputError, match='^hand.urdf: file not found: .*nowhere.urdf'):
        setup_from_doc(mutated(planar_doc, ('hand', 'urdf'), 'nowhere.urdf'))


def test_file_errors(tmp_path):
    with pytest.raises(InputError, match='^scenario: cannot read'):
        load_scenario(tmp_path / 'missing.yaml')
    bad = tmp_path / 'bad.yaml'
    bad.write_text('hand: [unclosed\n')
    with pytest.raises(InputError, match='^scenario: .* is not valid YAML'):
        load_scenario(bad)


def test_bundled_scenarios_load():
    paths = [p for p in sorted(CONFIG.glob('*.yaml'))
             if not p.stem.endswith(('_node', '_controllers'))]  # params files, not scenarios
    assert len(paths) >= 2
    for path in paths:
        s = load_scenario(path)
        assert s.friction.sides >= 3 and s.contacts


def test_defaults(planar_doc):
    doc = mutated(planar_doc, ('friction', 'min_normal_force'), None)
    s = parse_scenario(doc, Path(CONFIG))
    assert s.friction.min_normal_force == 0.0 and s.weights is None
