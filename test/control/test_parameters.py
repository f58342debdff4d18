# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""The node's parameter schema: the one source of declarations, checks, cycle and docs."""

import re

from conftest import ROOT
from grasp_torque_opt.backends import BACKENDS
from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings
from grasp_torque_opt.control.param_validators import check_pairs, Context
from grasp_torque_opt.control.parameters import (
    cycle_config,
    CycleConfig,
    POLICIES,
    SCHEMA,
    Schema,
    SCHEMA_FILE,
)
from grasp_torque_opt.core.certificate import DEFAULT_TOLERANCE
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.scenario import OBJECTIVES
import numpy as np
import pytest
import yaml

DESIGN = ROOT / 'docs' / 'design.md'


def test_the_docs_table_is_the_schemas():
    """docs/design.md section 4.4 holds the table the schema gives, and nothing else."""
    text = DESIGN.read_text()
    found = re.search(r'<!-- parameters: generated[^\n]*-->\n(.*?)<!-- parameters: end -->',
                      text, re.S)
    assert found, 'the generated table markers are missing from docs/design.md'
    assert found.group(1) == SCHEMA.markdown_table(), \
        'regenerate: python -m grasp_torque_opt.control.parameters'


def test_the_table_follows_a_change_of_the_file(tmp_path):
    """A changed entry changes the table (the check above can fail)."""
    doc = yaml.safe_load(SCHEMA_FILE.read_text())
    doc['grasp_torque_node']['hold_time']['default_value'] = 0.25
    path = tmp_path / 'p.yaml'
    path.write_text(yaml.safe_dump(doc))
    changed = Schema.load(path).markdown_table()
    assert changed != SCHEMA.markdown_table()
    assert '| `hold_time` | double | s | 0.25 |' in changed


def test_string_choices_are_the_codes():
    # POLICIES is read from the schema: the contract's names, held here.
    assert POLICIES == SCHEMA['fault_policy'].choices == ('hold', 'zero')
    assert SCHEMA['objective'].choices == OBJECTIVES
    assert SCHEMA['solver.backend'].choices == BACKENDS
    assert SCHEMA['solver.fallback'].choices == (*BACKENDS, 'none')


def test_defaults_agree_with_the_solver_and_certificate_settings():
    d = SCHEMA.defaults()
    s = ProxSuiteSettings()
    assert (d['solver.eps_abs'], d['solver.max_iter'], d['solver.max_iter_in']) == \
        (s.eps_abs, s.max_iter, s.max_iter_in)
    assert d['certificate_tolerance'] == DEFAULT_TOLERANCE
    assert d['solver.backend'] == BACKENDS[0]


def test_the_cycle_config_is_made_from_the_entries_with_a_cycle_key():
    fields = CycleConfig.__dataclass_fields__
    assert set(fields) == {s.cycle for s in SCHEMA.specs.values() if s.cycle}
    assert CycleConfig().joint_state_timeout == SCHEMA['joint_state_timeout'].default
    assert CycleConfig().method == SCHEMA['solver.method'].default
    values = {**SCHEMA.defaults(), 'gravity': [0.0, 9.81, 0.0], 'hold_time': 0.3}
    config = cycle_config(SCHEMA.params(values))
    assert config.gravity == (0.0, 9.81, 0.0) and config.hold_time == 0.3
    with pytest.raises(AttributeError):
        config.hold_time = 1.0  # frozen


def test_the_snapshot_is_frozen_and_typed():
    p = SCHEMA.params(SCHEMA.defaults())
    assert p.solver.backend == 'proxsuite' and p.joint_state_timeout == 0.1
    with pytest.raises(AttributeError):
        p.solver.backend = 'daqp'


@pytest.mark.parametrize('name, value, ctx, message', [
    ('polygon_sides', 2, Context(), 'polygon_sides: must be in [3, 64], got 2'),
    ('fault_policy', 'drop', Context(), 'fault_policy: must be one of hold, zero'),
    ('torque_limits', [1.0], Context(m=4), 'torque_limits: must have 4 entries, got 1'),
    ('torque_limits', [1.0, float('nan')], Context(m=2), 'torque_limits: must be finite'),
    ('weights', [1.0, 0.0], Context(m=2), 'weights: every entry must be > 0'),
    ('weights', [1e-6, 10.0], Context(m=2),
     'weights: the largest entry may be at most 1e+06 times the smallest, got 1e+07'),
    ('gravity', [0.0, 0.0, 200.0], Context(), 'gravity: norm must be at most 100 m/s^2'),
    ('object_origin', [0.0, 0.0], Context(), 'object_origin: must have 3 entries, got 2'),
    ('mu_tangential', float('inf'), Context(), 'mu_tangential: must be finite'),
    ('name_map', ['a'], Context(), 'name_map[0]: must be SCENARIO_NAME=URDF_NAME'),
    ('torque_limits', [0.5, 2.0], Context(m=2, joints=('a', 'b'),
                                          torque_bounds=np.array([1.0, 1.0])),
     "torque_limits: 2 N m for joint 'b' exceeds the URDF effort limit"),
])
def test_a_refused_value_names_the_parameter(name, value, ctx, message):
    with pytest.raises(InputError) as e:
        SCHEMA.check(name, value, ctx)
    assert str(e.value).startswith(message)


def test_accepted_values_pass():
    for name, value in SCHEMA.defaults().items():
        SCHEMA.check(name, value)
    SCHEMA.check('torque_limits', [0.5, 0.7], Context(m=2, torque_bounds=np.ones(2)))


def test_min_max_needs_tau_qp():
    check_pairs({'objective': 'min-max', 'solver.method': 'tau-qp'})
    with pytest.raises(InputError, match='^objective: min-max needs solver.method tau-qp'):
        check_pairs({'objective': 'min-max', 'solver.method': 'tau-qp-adaptive'})
