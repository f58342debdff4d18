# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""The node's parameter schema: the one source of declarations, checks, cycle and docs."""

import copy
import dataclasses
from pathlib import Path
import re
import subprocess
import sys

from conftest import CONFIG, ROOT, scenario_doc
from grasp_torque_opt.backends import BACKENDS
from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings
from grasp_torque_opt.backends.registry import REGISTRY
from grasp_torque_opt.control.parameters import generated
from grasp_torque_opt.control.parameters.generate import render
from grasp_torque_opt.control.parameters.generated import CycleConfig, Params
from grasp_torque_opt.control.parameters.schema import (
    POLICIES,
    PYTHON_TYPES,
    SCHEMA,
    Schema,
    SCHEMA_FILE,
)
from grasp_torque_opt.control.parameters.snapshot import cycle_config, params_from
from grasp_torque_opt.control.parameters.validators import check_pairs, Context, REGISTRY_CHOICES
from grasp_torque_opt.core.certificate import DEFAULT_TOLERANCE
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.scenario import OBJECTIVES, parse_scenario
import numpy as np
import pytest
import yaml

NODE_PAGE = ROOT / 'docs' / 'node.md'


def test_the_docs_table_is_the_schemas():
    """docs/node.md ("Parameters") holds the table the schema gives, and nothing else."""
    text = NODE_PAGE.read_text()
    found = re.search(r'<!-- parameters: generated[^\n]*-->\n(.*?)<!-- parameters: end -->',
                      text, re.S)
    assert found, 'the generated table markers are missing from docs/node.md'
    assert found.group(1) == SCHEMA.markdown_table(), \
        'regenerate: python -m grasp_torque_opt.control.parameters'


def test_the_package_prints_the_table():
    """``python -m grasp_torque_opt.control.parameters`` (CONTRIBUTING.md) prints it."""
    out = subprocess.run([sys.executable, '-m', 'grasp_torque_opt.control.parameters'],
                         capture_output=True, text=True, check=True, cwd=ROOT).stdout
    assert out == SCHEMA.markdown_table()


def test_the_generated_module_is_the_schemas():
    """generated.py is what the generator writes from the schema today: not stale."""
    assert Path(generated.__file__).read_text() == render(SCHEMA), \
        'stale: regenerate with python -m grasp_torque_opt.control.parameters.generate'


def test_the_generated_module_follows_a_change_of_the_file(tmp_path):
    """A changed entry changes the generated text (the check above can fail)."""
    doc = yaml.safe_load(SCHEMA_FILE.read_text())
    doc['grasp_torque_node']['hold_time']['default_value'] = 0.25
    doc['grasp_torque_node']['solver']['new_option'] = {
        'type': 'int', 'default_value': 3, 'unit': '-', 'description': 'A new option.'}
    path = tmp_path / 'p.yaml'
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    text = render(Schema.load(path))
    assert '    hold_time: float = 0.25\n' in text and '    new_option: int | None\n' in text
    assert text != render(SCHEMA)


def _leaves(cls: type, prefix: str = '') -> dict[str, object]:
    """Dotted name -> field type, through the namespaces' classes."""
    out = {}
    for f in dataclasses.fields(cls):
        if dataclasses.is_dataclass(f.type):
            out.update(_leaves(f.type, f'{prefix}{f.name}.'))
        else:
            out[f'{prefix}{f.name}'] = f.type
    return out


def test_the_generated_classes_have_every_entry_typed():
    assert list(_leaves(Params)) == list(SCHEMA)  # every entry, in declaration order
    for name, kind in _leaves(Params).items():
        assert kind == PYTHON_TYPES[SCHEMA[name].type] | None, name
    cycle = [s for s in SCHEMA.specs.values() if s.cycle]
    assert [f.name for f in dataclasses.fields(CycleConfig)] == [s.cycle for s in cycle]
    for f, s in zip(dataclasses.fields(CycleConfig), cycle):
        assert (f.type, f.default) == (PYTHON_TYPES[s.type], s.default), f.name
    assert CycleConfig.__dataclass_params__.frozen and Params.__dataclass_params__.frozen


def test_backend_choices_come_from_the_registry(monkeypatch):
    """The YAML names the registry (one_of_backends), the loader fills in its names."""
    raw = yaml.safe_load(SCHEMA_FILE.read_text())['grasp_torque_node']['solver']
    assert 'one_of<>' not in raw['backend']['validation']
    assert 'one_of<>' not in raw['fallback']['validation']
    monkeypatch.setitem(REGISTRY_CHOICES, 'one_of_backends', (*BACKENDS, 'osqp'))
    again = Schema.load()
    assert again['solver.backend'].choices == (*BACKENDS, 'osqp')
    assert again['solver.fallback'].choices == (*BACKENDS, 'osqp', 'none')
    assert again.reason('solver.backend', 'cvxopt') == \
        f"solver.backend: must be one of {', '.join((*BACKENDS, 'osqp'))}"


def test_the_warm_start_rule_is_the_registrys():
    """The registry's entry says that quadprog has no warm start, not the node."""
    assert not REGISTRY['quadprog'].warm_start
    assert REGISTRY['proxsuite'].warm_start and REGISTRY['daqp'].warm_start


@pytest.mark.parametrize('name', ['planar_two_finger.yaml', 'allegro_right.yaml'])
def test_scenario_defaults_come_from_the_entries(name):
    scenario = parse_scenario(copy.deepcopy(scenario_doc(CONFIG / name)), CONFIG)
    setup = GraspSetup.from_scenario(scenario)
    d = SCHEMA.scenario_defaults({'scenario': scenario, 'setup': setup})
    assert list(d) == [s.name for s in SCHEMA.specs.values() if s.from_scenario is not None]
    assert d['joints'] == list(setup.hand.joints)
    assert d['torque_limits'] == [float(x) for x in setup.hand.torque_limits]
    assert (d['mu_tangential'], d['polygon_sides']) == \
        (setup.friction.mu1, setup.friction.sides)
    assert d['torque_limits_above_urdf'] is scenario.torque_limits_above_urdf
    gravity = SCHEMA['gravity'].default if scenario.gravity is None else scenario.gravity
    assert d['gravity'] == [float(x) for x in gravity]
    for key, value in d.items():  # each in its own type, as rclpy declares it
        SCHEMA.check(key, tuple(value) if isinstance(value, list) else value)


def test_a_from_scenario_entry_names_its_field(tmp_path):
    doc = yaml.safe_load(SCHEMA_FILE.read_text())
    doc['grasp_torque_node']['mu_tangential']['from_scenario'] = 'scenario'
    path = tmp_path / 'p.yaml'
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ValueError, match='mu_tangential: from_scenario must be'):
        Schema.load(path)


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
    config = cycle_config(params_from(values))
    assert config.gravity == (0.0, 9.81, 0.0) and config.hold_time == 0.3
    with pytest.raises(AttributeError):
        config.hold_time = 1.0  # frozen


def test_the_snapshot_is_frozen_and_typed():
    p = params_from(SCHEMA.defaults())
    assert p.solver.backend == 'proxsuite' and p.joint_state_timeout == 0.1
    with pytest.raises(AttributeError):
        p.solver.backend = 'daqp'


@pytest.mark.parametrize('name, value, ctx, message', [
    ('polygon_sides', 2, Context(), 'polygon_sides: must be in [3, 64], got 2'),
    # Issue 33: 0.001 N m/s kept outdated torques for 31 s; a change of d N m now takes
    # at most d seconds.
    ('max_torque_rate', 1e-3, Context(), 'max_torque_rate: must be in [1.0, '),
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
