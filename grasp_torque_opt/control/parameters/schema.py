# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The node's parameter schema read, without ROS: the loader.

``grasp_torque_opt/control/grasp_torque_node_parameters.yaml`` is written in
generate_parameter_library's format (ros2_controllers' ``*_parameters.yaml``): one
entry per parameter with its type, default, description, read-only flag and
validation. generate_parameter_library is a C++/Python code generator of the ROS
build that is not on the package registry, so this module reads the same format
itself. From the file come:

- :data:`SCHEMA`, the parameters in order (:class:`ParamSpec`), with
  :meth:`Schema.check` (the validation that names the parameter), the scenario's
  defaults (:meth:`Schema.scenario_defaults`) and the docs table
  (:meth:`Schema.markdown_table`, docs/node.md, "Parameters");
- the typed module :mod:`~grasp_torque_opt.control.parameters.generated`
  (``CycleConfig``, the ``Params`` snapshot), written from :data:`SCHEMA` by
  :mod:`~grasp_torque_opt.control.parameters.generate`.

The ROS side (declarations, descriptors, topic-name checks) is
:mod:`grasp_torque_opt.ros.node.parameters`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
import math
from pathlib import Path
from typing import Any

from grasp_torque_opt.control.parameters.validators import (
    BUILT_IN,
    Context,
    REGISTRY_CHOICES,
    Validator,
    VALIDATORS,
)
from grasp_torque_opt.core.exceptions import InputError
import yaml

#: The schema file.
SCHEMA_FILE = Path(__file__).parent.parent / 'grasp_torque_node_parameters.yaml'
#: Python types of the schema's types.
PYTHON_TYPES = {'string': str, 'double': float, 'int': int, 'bool': bool,
                'string_array': tuple, 'double_array': tuple}
#: Validators that fix an array's length: run first, as the others index it.
SIZE_VALIDATORS = ('fixed_size<>', 'size_of_joints')
#: What a ``from_scenario`` field is read from: the scenario, or the grasp bound to its hand.
SCENARIO_SOURCES = ('scenario', 'setup')


@dataclass(frozen=True)
class ParamSpec:
    """
    One parameter of the schema.

    Attributes:
        name: dotted name (``solver.backend``).
        type: ``string``, ``double``, ``int``, ``bool``, ``string_array`` or
            ``double_array``.
        description: what it does.
        unit: its SI unit ('-' for none).
        default: the default value (None: none: from the scenario, or unset).
        read_only: fixed after start (the managed node: while configured).
        from_scenario: where the scenario gives the default, in words (None: not).
        scenario_field: the attribute that gives it, from one of
            :data:`SCENARIO_SOURCES` (``setup.friction.mu1``; None: not from the
            scenario).
        unset: the words for a parameter without a default that may stay unset.
        cycle: the ``CycleConfig`` field that takes it (None: none).
        validation: (validator, arguments) in the file's order.
    """

    name: str
    type: str  # noqa: A003 -- generate_parameter_library's word
    description: str
    unit: str
    default: Any = None
    read_only: bool = False
    from_scenario: str | None = None
    scenario_field: str | None = None
    unset: str | None = None
    cycle: str | None = None
    validation: tuple[tuple[str, tuple], ...] = ()

    def argument(self, validator: str) -> tuple | None:
        """Give a validator's arguments, or None when the entry does not use it."""
        return next((args for v, args in self.validation if v == validator), None)

    @property
    def bounds(self) -> tuple[Any, Any] | None:
        """Give (low, high), inclusive, or None."""
        args = self.argument('bounds<>')
        return (args[0], args[1]) if args else None

    @property
    def choices(self) -> tuple[str, ...] | None:
        """Give the values allowed, or None."""
        args = self.argument('one_of<>')
        return tuple(args[0]) if args else None


def _from_scenario(name: str, entry: Mapping[str, Any]) -> tuple[str | None, str | None]:
    """Read an entry's ``from_scenario: {field: SOURCE.ATTRIBUTE..., docs: WORDS}``."""
    given = entry.get('from_scenario')
    if given is None:
        return None, None
    field = given.get('field', '') if isinstance(given, Mapping) else ''
    if field.partition('.')[0] not in SCENARIO_SOURCES or 'docs' not in given:
        raise ValueError(f'{SCHEMA_FILE.name}: {name}: from_scenario must be '
                         f"{{field: {'|'.join(SCENARIO_SOURCES)}.ATTRIBUTE, docs: WORDS}}, "
                         f'got {given!r}')
    return str(given['docs']), field


def _validation(entry: Mapping[str, Any]) -> tuple[tuple[str, tuple], ...]:
    """
    Read an entry's validators, in order, with a registry's choices filled in.

    ``one_of_backends: [[none]]`` becomes ``one_of<>: [[proxsuite, daqp, quadprog, none]]``
    (:data:`~grasp_torque_opt.control.parameters.validators.REGISTRY_CHOICES`).
    """
    out = []
    for validator, args in (entry.get('validation') or {}).items():
        args = tuple(args or ())
        if validator in REGISTRY_CHOICES:
            extra = tuple(args[0]) if args else ()
            validator, args = 'one_of<>', ((*REGISTRY_CHOICES[validator], *extra),)
        out.append((validator, args))
    return tuple(out)


def _entries(tree: Mapping[str, Any], prefix: str = '') -> list[ParamSpec]:
    """Flatten the file's nested maps into specs, in the file's order."""
    out = []
    for key, entry in tree.items():
        name = f'{prefix}{key}'
        if 'type' not in entry:  # a namespace (solver.*)
            out += _entries(entry, f'{name}.')
            continue
        if entry['type'] not in PYTHON_TYPES:
            raise ValueError(f'{SCHEMA_FILE.name}: {name}: unknown type {entry["type"]!r}')
        cycle = entry.get('cycle')
        default = entry.get('default_value')
        words, field = _from_scenario(name, entry)
        out.append(ParamSpec(
            name=name, type=entry['type'], description=' '.join(entry['description'].split()),
            unit=str(entry.get('unit', '-')),
            default=tuple(default) if isinstance(default, list) else default,
            read_only=bool(entry.get('read_only', False)),
            from_scenario=words, scenario_field=field, unset=entry.get('unset'),
            cycle=(key if cycle is True else cycle) or None, validation=_validation(entry)))
    return out


class Schema:
    """The parameters of one node, in declaration order, and their checks."""

    def __init__(self, specs: list[ParamSpec], validators: Mapping[str, Validator]) -> None:
        """Hold the specs and the custom validators they may name."""
        self.specs: dict[str, ParamSpec] = {s.name: s for s in specs}
        self.validators = dict(validators)

    @classmethod
    def load(cls, path: Path = SCHEMA_FILE, node: str = 'grasp_torque_node') -> Schema:
        """Read a generate_parameter_library file (the top key is the node's)."""
        with open(path, encoding='utf-8') as f:
            doc = yaml.safe_load(f)
        return cls(_entries(doc[node]), VALIDATORS)

    def with_validators(self, **validators: Validator) -> Schema:
        """Give the same schema with more custom validators (the ROS side's)."""
        return Schema(list(self.specs.values()), {**self.validators, **validators})

    def __iter__(self):
        """Iterate over the parameters' names, in declaration order."""
        return iter(self.specs)

    def __getitem__(self, name: str) -> ParamSpec:
        """Give a parameter's spec."""
        return self.specs[name]

    def __contains__(self, name: object) -> bool:
        """Say whether the schema has the parameter."""
        return name in self.specs

    def defaults(self) -> dict[str, Any]:
        """Give the defaults of the parameters that have one, not from the scenario."""
        return {s.name: list(s.default) if isinstance(s.default, tuple) else s.default
                for s in self.specs.values()
                if s.default is not None and s.from_scenario is None}

    def scenario_defaults(self, sources: Mapping[str, Any]) -> dict[str, Any]:
        """
        Give the defaults that come from the scenario, each read where its entry says.

        Args:
            sources: :data:`SCENARIO_SOURCES` -> the object (``scenario``: the
                :class:`~grasp_torque_opt.core.scenario.Scenario`; ``setup``: the
                :class:`~grasp_torque_opt.core.grasp_setup.GraspSetup` bound to its hand).

        Returns:
            name -> value in the parameter's own type (lists for arrays), in declaration
            order; where the scenario gives none (None), the entry's ``default_value``.
        """
        out = {}
        for s in self.specs.values():
            if s.scenario_field is None:
                continue
            source, *path = s.scenario_field.split('.')
            value = sources[source]
            for part in path:
                value = getattr(value, part)
            out[s.name] = _plain(s, s.default if value is None else value)
        return out

    def reason(self, name: str, value: Any, ctx: Context = Context()) -> str:
        """Say why a value is refused, 'NAME: PROBLEM' ('' if it is accepted)."""
        try:
            self.check(name, value, ctx)
        except InputError as e:
            return str(e)
        return ''

    def check(self, name: str, value: Any, ctx: Context = Context()) -> None:
        """
        Check one value against its entry.

        Sizes first, then finiteness (doubles), then the entry's validators in order.

        Raises:
            InputError: naming the parameter (or its entry) and the problem.
        """
        spec = self.specs[name]
        order = sorted(spec.validation, key=lambda v: v[0] not in SIZE_VALIDATORS)
        sized = [v for v in order if v[0] in SIZE_VALIDATORS]
        for validator, args in sized:
            self._run(spec, validator, args, value, ctx)
        if spec.type == 'double' and not math.isfinite(value):
            raise InputError(name, 'must be finite')
        if spec.type == 'double_array' and not all(math.isfinite(v) for v in value):
            raise InputError(name, 'must be finite')
        for validator, args in order[len(sized):]:
            self._run(spec, validator, args, value, ctx)

    def _run(self, spec: ParamSpec, validator: str, args: tuple, value: Any,
             ctx: Context) -> None:
        if validator in BUILT_IN:
            problem = BUILT_IN[validator](spec.name, value, args, ctx)
        elif validator in self.validators:
            problem = self.validators[validator](spec.name, value, ctx)
        else:
            return  # a ROS validator, checked where ROS is (ros.node.parameters)
        if problem:
            raise InputError(spec.name, problem)

    def markdown_table(self) -> str:
        """Write the parameter table of docs/node.md, "Parameters"."""
        rows = ['| parameter | type | unit | default | range, meaning |',
                '|---|---|---|---|---|']
        for s in self.specs.values():
            rows.append(f'| `{s.name}` | {_type_words(s)} | {s.unit} | {_default_words(s)} '
                        f'| {_meaning(s)} |')
        return '\n'.join(rows) + '\n'


def _plain(s: ParamSpec, value: Any) -> Any:
    """Give a value in the parameter's type, as rclpy takes it (arrays as lists)."""
    if value is None or not s.type.endswith('_array'):
        return None if value is None else PYTHON_TYPES[s.type](value)
    item = str if s.type == 'string_array' else float
    return [item(x) for x in value]


def _type_words(s: ParamSpec) -> str:
    if not s.type.endswith('_array'):
        return s.type
    size = s.argument('fixed_size<>')
    n = size[0] if size else 'm' if s.argument('size_of_joints') is not None else ''
    return f"{s.type.partition('_')[0]}[{n}]"


def _value_words(v: Any) -> str:
    if isinstance(v, bool):
        return str(v).lower()
    if isinstance(v, str):
        return f'"{v}"' if v == '' else v
    if isinstance(v, tuple):
        return '[' + ', '.join(_value_words(x) for x in v) + ']'
    return f'{v:g}' if isinstance(v, float) else str(v)


def _default_words(s: ParamSpec) -> str:
    if s.name == 'scenario':
        return '(required)'
    if s.from_scenario is not None:
        return s.from_scenario
    if s.unset is not None:
        return s.unset
    return _value_words(s.default)


def _meaning(s: ParamSpec) -> str:
    parts = []
    if s.bounds is not None:
        low, high = s.bounds
        parts.append(f'[{_value_words(low)}, {_value_words(high)}]')
    if s.choices is not None:
        parts.append('one of ' + ', '.join(f'`{c}`' for c in s.choices))
    text = s.description.replace('|', '\\|')
    parts.append(text + (' Read-only.' if s.read_only else ''))
    return '; '.join(parts)


#: The node's parameters.
SCHEMA = Schema.load()
#: The fault policies: keep the last certified command, or publish zero torques.
POLICIES = SCHEMA['fault_policy'].choices
