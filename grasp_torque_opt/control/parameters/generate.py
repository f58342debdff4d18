# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Write the typed parameters module from the schema, as generate_parameter_library does.

``python -m grasp_torque_opt.control.parameters.generate`` writes
:mod:`~grasp_torque_opt.control.parameters.generated` (``generated.py`` beside this
module): :class:`CycleConfig` (the entries with a ``cycle`` key, with their types and
defaults) and the frozen ``Params`` tree (one class per namespace, every value typed
``T | None``), every field written out. ``--check`` only says whether the file is the
one the schema gives (exit 1 if not); test/control/test_parameters.py does the same.
"""

from __future__ import annotations

import argparse
import builtins
from pathlib import Path
import sys
import textwrap
from typing import Any

from grasp_torque_opt.control.parameters.schema import ParamSpec, PYTHON_TYPES, SCHEMA, Schema

#: The file this writes.
GENERATED_FILE = Path(__file__).with_name('generated.py')
#: The longest line flake8 allows.
LINE = 99
#: A space that the docstrings' wrapping keeps (inside a unit: ``[N m/s]``).
_KEEP = '\u00a0'

_HEADER = '''\
# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

# Generated from grasp_torque_opt/control/grasp_torque_node_parameters.yaml by
# python -m grasp_torque_opt.control.parameters.generate: do not edit, regenerate.

"""
The node's parameters as typed, frozen dataclasses, generated from the schema.

As generate_parameter_library writes a node's parameters module, every field is written
out with its type (and, for :class:`CycleConfig`, its default) from
``grasp_torque_node_parameters.yaml``; test/control/test_parameters.py fails when this
file is not the one the schema gives.

- :class:`CycleConfig`: the cycle's settings, one field per entry with a ``cycle`` key.
- :class:`Params`: the frozen snapshot of every value (``p.solver.backend``), one class
  per namespace, a value None while the parameter has none
  (:mod:`~grasp_torque_opt.control.parameters.snapshot` makes and reads it).
- :data:`CYCLE_FIELDS`: each :class:`CycleConfig` field's parameter.
"""

from dataclasses import dataclass
'''


def class_name(path: tuple[str, ...]) -> str:
    """``('contact_geometry',)`` -> ``ParamsContactGeometry``; ``()`` -> ``Params``."""
    return 'Params' + ''.join(part.title().replace('_', '') for part in path)


def _tree(schema: Schema) -> dict[str, Any]:
    """Nest the specs by their dotted names: namespace -> {key: spec or namespace}."""
    tree: dict[str, Any] = {}
    for s in schema.specs.values():
        *path, leaf = s.name.split('.')
        node = tree
        for part in path:
            node = node.setdefault(part, {})
        node[leaf] = s
    return tree


def _doc_item(name: str, text: str) -> list[str]:
    """Write an ``Attributes:`` item of a docstring, wrapped to the line length."""
    text = text.replace('\\', '\\\\')
    lines = textwrap.wrap(f'{name}: {text}', LINE, initial_indent=' ' * 8,
                          subsequent_indent=' ' * 12, break_on_hyphens=False)
    return [line.replace(_KEEP, ' ') for line in lines]


def _noqa(name: str) -> str:
    """Mark a field named as a builtin (``effort_estimation.filter``) for flake8."""
    return "  # noqa: A003 -- the parameter's name" if hasattr(builtins, name) else ''


def _docstring(summary: str, items: list[tuple[str, str]]) -> list[str]:
    lines = ['    """', f'    {summary}', '', '    Attributes:']
    for name, text in items:
        lines += _doc_item(name, text)
    return lines + ['    """', '']


def _words(s: ParamSpec) -> str:
    """Give a parameter's description with its unit, for a field's docstring item."""
    unit = '' if s.unit == '-' else ' [' + s.unit.replace(' ', _KEEP) + ']'
    return s.description + unit


def _cycle_class(schema: Schema) -> list[str]:
    specs = [s for s in schema.specs.values() if s.cycle]
    items = [(s.cycle, ('' if s.cycle == s.name else f'(``{s.name}``) ') + _words(s))
             for s in specs]
    lines = ['', '', '@dataclass(frozen=True)', 'class CycleConfig:']
    lines += _docstring('Timing and safety settings of the cycle: the entries with a '
                        '``cycle`` key.', items)
    for s in specs:
        lines.append(f'    {s.cycle}: {PYTHON_TYPES[s.type].__name__} = {s.default!r}'
                     + _noqa(s.cycle))
    return lines


def _params_classes(tree: dict[str, Any], path: tuple[str, ...] = ()) -> list[str]:
    """Write a namespace's class, after the classes of the namespaces in it."""
    lines: list[str] = []
    items, body = [], []
    for key, sub in tree.items():
        if isinstance(sub, ParamSpec):
            items.append((key, _words(sub)))
            body.append(f'    {key}: {PYTHON_TYPES[sub.type].__name__} | None{_noqa(key)}')
        else:
            lines += _params_classes(sub, (*path, key))
            items.append((key, f'the ``{".".join((*path, key))}.*`` parameters.'))
            body.append(f'    {key}: {class_name((*path, key))}')
    summary = ('The frozen snapshot of every parameter, one class per namespace.' if not path
               else f'The ``{".".join(path)}.*`` parameters.')
    lines += ['', '', '@dataclass(frozen=True)', f'class {class_name(path)}:']
    lines += _docstring(summary, items)
    return lines + body


def _cycle_fields(schema: Schema) -> list[str]:
    lines = ['', '', '#: CycleConfig field -> the parameter that gives it.', 'CYCLE_FIELDS = {']
    lines += [f'    {s.cycle!r}: {s.name!r},' for s in schema.specs.values() if s.cycle]
    return lines + ['}']


def render(schema: Schema = SCHEMA) -> str:
    """Give the text of the typed parameters module of ``schema``."""
    lines = [_HEADER.rstrip('\n')]
    lines += _cycle_class(schema)
    lines += _params_classes(_tree(schema))
    lines += _cycle_fields(schema)
    return '\n'.join(lines) + '\n'


def main(argv: list[str] | None = None) -> int:
    """Write (or, with ``--check``, compare) the generated module; give the exit code."""
    parser = argparse.ArgumentParser(prog='python -m grasp_torque_opt.control.parameters.generate',
                                     description=__doc__.strip().splitlines()[0])
    parser.add_argument('--check', action='store_true',
                        help='only say whether the file is up to date (exit 1 if not)')
    args = parser.parse_args(argv)
    text = render()
    if args.check:
        fresh = GENERATED_FILE.exists() and GENERATED_FILE.read_text() == text
        print(f'{GENERATED_FILE.name}: ' + ('up to date' if fresh else
                                            'stale: run python -m '
                                            'grasp_torque_opt.control.parameters.generate'))
        return 0 if fresh else 1
    GENERATED_FILE.write_text(text)
    print(f'wrote {GENERATED_FILE}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
