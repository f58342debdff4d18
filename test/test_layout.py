# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The package's layers (docs/architecture.md): no module imports a family above its own."""

import ast
from pathlib import Path

from conftest import ROOT

PACKAGE = ROOT / 'grasp_torque_opt'
#: Family -> rank; a module may import its own family and families of a lower rank.
RANKS = {'core': 0, 'backends': 1, 'reference': 1, 'methods': 2, 'control': 3, 'sim': 3,
         'ros': 4, 'cli': 4}


def family(module: str) -> str:
    """``grasp_torque_opt.core.hand`` -> ``core``; ``grasp_torque_opt.cli`` -> ``cli``."""
    return module.split('.')[1]


def imports(path: Path) -> set[str]:
    """Every grasp_torque_opt module that ``path`` imports, at any depth of its code."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module] + [f'{node.module}.{a.name}' for a in node.names]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        found.update(n for n in names[:1] if n.startswith('grasp_torque_opt.'))
        if isinstance(node, ast.ImportFrom) and node.module == 'grasp_torque_opt':
            found.update(f'grasp_torque_opt.{a.name}' for a in node.names)
    return found


def modules() -> dict[str, Path]:
    out = {}
    for path in PACKAGE.rglob('*.py'):
        parts = path.relative_to(ROOT).with_suffix('').parts
        if parts[-1] == '__init__':
            parts = parts[:-1]
        if len(parts) > 1:  # the package's own __init__ only maps public names lazily
            out['.'.join(parts)] = path
    return out


def test_every_module_belongs_to_a_known_family():
    unknown = {m for m in modules() if family(m) not in RANKS}
    assert not unknown, f'modules outside the families of docs/architecture.md: {unknown}'


def test_no_module_imports_a_family_above_its_own():
    wrong = []
    for module, path in modules().items():
        mine = family(module)
        for other in imports(path):
            theirs = family(other)
            if theirs != mine and RANKS[theirs] >= RANKS[mine]:
                wrong.append(f'{module} imports {other}')
    assert not wrong, '\n'.join(wrong)


def test_the_parser_sees_imports_at_module_and_function_level():
    """The parser finds imports inside functions too (e.g. a lazy import of the node)."""
    code = PACKAGE / 'core' / 'grasp_maps.py'
    assert 'grasp_torque_opt.core.hand' in imports(code)
    sample = ROOT / 'test' / 'ros_harness.py'
    assert 'grasp_torque_opt.ros.node' in imports(sample)


#: The size rule (docs/architecture.md): a module a newcomer reads in one sitting.
MAX_MODULE_LINES = 500
MAX_CLASS_LINES = 300


def test_no_module_or_class_is_too_long_to_read():
    long = []
    for module, path in modules().items():
        text = path.read_text()
        if text.count('\n') > MAX_MODULE_LINES:
            long.append(f'{module}: {text.count(chr(10))} lines (at most {MAX_MODULE_LINES})')
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ClassDef):
                n = node.end_lineno - node.lineno + 1
                if n > MAX_CLASS_LINES:
                    long.append(f'{module}.{node.name}: {n} lines (at most {MAX_CLASS_LINES})')
    assert not long, '\n'.join(long)


#: The function rule (issue 31, the house style): one job, at most about 80 lines.
MAX_FUNCTION_LINES = 80


def test_no_function_is_too_long_to_read():
    """Every function of the package and of bench/, methods and nested ones each on its own."""
    long = []
    for folder in (PACKAGE, ROOT / 'bench'):
        for path in sorted(folder.rglob('*.py')):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    n = node.end_lineno - node.lineno + 1
                    if n > MAX_FUNCTION_LINES:
                        long.append(f'{path.relative_to(ROOT)}:{node.lineno} {node.name}: '
                                    f'{n} lines (at most {MAX_FUNCTION_LINES})')
    assert not long, '\n'.join(long)
