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
RANKS = {'core': 0, 'backends': 1, 'native': 1, 'reference': 1, 'methods': 2, 'control': 3,
         'sim': 3, 'ros': 4, 'cli': 4}


def family(module: str) -> str:
    """``grasp_torque_opt.core.hand`` -> ``core``; ``grasp_torque_opt.cli`` -> ``cli``."""
    return module.split('.')[1]


def loaded_by_name(node: ast.AST) -> str | None:
    """
    Return the module that an ``importlib.import_module(...)`` or ``__import__(...)`` names.

    A constant name, or the constant head of an f-string
    (``f'grasp_torque_opt.native.{name}'`` -> ``grasp_torque_opt.native``); None for
    any other node or a name that is not the package's.
    """
    if not isinstance(node, ast.Call) or not node.args:
        return None
    f = node.func
    called = f.attr if isinstance(f, ast.Attribute) else getattr(f, 'id', '')
    if called not in ('import_module', '__import__'):
        return None
    arg = node.args[0]
    if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
        name = arg.value
    elif isinstance(arg, ast.JoinedStr) and arg.values and isinstance(arg.values[0], ast.Constant):
        name = str(arg.values[0].value).rstrip('.')
    else:
        return None
    return name if name.startswith('grasp_torque_opt.') else None


def imports(path: Path) -> set[str]:
    """Every grasp_torque_opt module that ``path`` imports, at any depth, by name too."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        by_name = loaded_by_name(node)
        if by_name:
            found.add(by_name)
            continue
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


def test_the_parser_sees_modules_loaded_by_name():
    """importlib.import_module with the package's name (an f-string's head too) counts."""
    assert 'grasp_torque_opt.native' in imports(PACKAGE / 'native' / 'loader.py')
    call = ast.parse("importlib.import_module(f'grasp_torque_opt.ros.{x}')").body[0].value
    assert loaded_by_name(call) == 'grasp_torque_opt.ros'
    assert loaded_by_name(ast.parse("__import__('numpy')").body[0].value) is None


def _type_checking_only(tree: ast.Module) -> set[int]:
    """Return the ids of the nodes under ``if TYPE_CHECKING:`` (type hints, never run)."""
    skip = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and getattr(node.test, 'id', None) == 'TYPE_CHECKING':
            skip.update(id(n) for part in node.body for n in ast.walk(part))
    return skip


def import_graph() -> dict[str, set[str]]:
    """
    Map each module to the package's modules it imports when run (any level).

    ``from a.b import c`` is the module ``a.b.c`` where that is a module, else ``a.b``;
    imports under ``if TYPE_CHECKING:`` are left out (a composition root's parts may
    name its type), and so is the package's own ``__init__`` (it maps names lazily).
    """
    mods = modules()
    graph = {}
    for module, path in mods.items():
        tree = ast.parse(path.read_text())
        skip = _type_checking_only(tree)
        out = set()
        for node in ast.walk(tree):
            if id(node) in skip:
                continue
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [f'{node.module}.{a.name}' if f'{node.module}.{a.name}' in mods
                         else node.module for a in node.names]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            else:
                names = [loaded_by_name(node)] if loaded_by_name(node) else []
            for name in names:
                while name and name not in mods:
                    name = name.rpartition('.')[0]
                if name and name != module:
                    out.add(name)
        graph[module] = out
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Return the import circles: strongly connected components of two modules or more."""
    index, low, stack, on, found = {}, {}, [], set(), []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            part = []
            while True:
                w = stack.pop()
                on.discard(w)
                part.append(w)
                if w == v:
                    break
            if len(part) > 1:
                found.append(sorted(part))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_no_import_circle():
    """No module imports itself through others, at module or function level."""
    found = cycles(import_graph())
    assert not found, '\n'.join(' <-> '.join(c) for c in found)


def test_the_circle_finder_finds_one():
    assert cycles({'a': {'b'}, 'b': {'c'}, 'c': {'a'}, 'd': {'a'}}) == [['a', 'b', 'c']]


def defined_names(path: Path) -> tuple[set[str], set[str]]:
    """Return (names a module defines, names it imports from the package), top level."""
    defined, imported = set(), set()
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            defined.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            for target in node.targets if isinstance(node, ast.Assign) else [node.target]:
                defined.update(n.id for n in ast.walk(target) if isinstance(n, ast.Name))
        elif isinstance(node, ast.ImportFrom) and (node.module or '').startswith(
                'grasp_torque_opt'):
            imported.update(a.asname or a.name for a in node.names)
    return defined, imported


def test_no_module_but_an_init_re_exports_another_modules_names():
    """
    A name is imported from the module that defines it, never through another module.

    A package's ``__init__`` may gather its family's names; no other module passes on
    what it imported (a shim left 'to keep imports working' becomes the real path).
    """
    mods = modules()
    files = [*PACKAGE.rglob('*.py'), *(ROOT / 'test').rglob('*.py'),
             *(ROOT / 'bench').glob('*.py')]
    wrong = []
    for path in files:
        for node in ast.walk(ast.parse(path.read_text())):
            if not (isinstance(node, ast.ImportFrom) and node.level == 0
                    and node.module in mods and mods[node.module].name != '__init__.py'):
                continue
            defined, imported = defined_names(mods[node.module])
            wrong.extend(f'{path.relative_to(ROOT)}:{node.lineno} takes {a.name} from '
                         f'{node.module}, which imports it' for a in node.names
                         if a.name in imported and a.name not in defined)
    assert not wrong, '\n'.join(wrong)


def architecture_rows() -> set[str]:
    """
    Return the modules that docs/architecture.md's tables name, as ``family.module``.

    A row is ``| family | modules | holds |``; an empty family cell is the row above's
    (``ros/node/`` is a family of its own there), modules are backticked, commas apart.
    """
    listed, family = set(), ''
    for line in (ROOT / 'docs' / 'architecture.md').read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip('|').split('|')]
        if not line.startswith('|') or len(cells) < 3 or set(cells[1]) <= set('-: '):
            continue
        family = cells[0].strip('`').strip('/').replace('/', '.') or family
        listed.update(f'{family}.{name.strip("`")}' for name in cells[1].split(', ')
                      if name.startswith('`'))
    return listed


def test_every_module_is_in_the_architecture_table():
    """docs/architecture.md's table names every module of the package, each in its row."""
    listed = architecture_rows()
    missing = []
    for module, path in modules().items():
        key = module.split('.', 1)[1]
        if path.name == '__init__.py':
            key += '.__init__'
        if path.name != '__main__.py' and key not in listed:
            missing.append(module)
    assert not missing, 'not in docs/architecture.md: ' + ', '.join(sorted(missing))


def test_the_public_api_holds_what_a_planner_and_a_driver_need():
    """Every name of the package's __all__ imports, the planner's loop among them."""
    import grasp_torque_opt

    for name in ('plan_grasps', 'PlanSettings', 'rank', 'format_table', 'score_batch',
                 'GraspSetup', 'solve', 'load_capacity'):
        assert name in grasp_torque_opt.__all__, name
    for name in grasp_torque_opt.__all__:
        assert getattr(grasp_torque_opt, name) is not None, name


def test_the_readme_is_read_in_one_sitting():
    """README.md at most 200 lines: the two commands, a tour, the pages (figures live in docs/)."""
    assert (ROOT / 'README.md').read_text().count('\n') <= 200


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
