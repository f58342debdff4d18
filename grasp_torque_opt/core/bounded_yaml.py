# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
YAML read within bounds: no aliases, nesting bounded, errors with line and column.

A scenario never needs an alias, and 2.8 KB of nested aliases expand to billions of
values (the "billion laughs"); the composer recurses once per level (5000 levels
raised RecursionError).
"""

from __future__ import annotations

from grasp_torque_opt.core.exceptions import cut, InputError
import yaml

#: Deepest nesting accepted in a scenario file.
MAX_DEPTH = 16


class BoundedLoader(yaml.SafeLoader):
    """
    PyYAML's SafeLoader without aliases and with nesting bounded by :data:`MAX_DEPTH`.

    An alias repeats a node by reference, so 2.8 KB of nested aliases expand to
    billions of values (the "billion laughs"); a scenario never needs one. The
    composer recurses once per level (5000 levels raised RecursionError).
    """

    _depth = 0

    def compose_node(self, parent, index):
        if self.check_event(yaml.AliasEvent):
            mark = self.peek_event().start_mark
            raise InputError('scenario', f'YAML aliases are not allowed (line {mark.line + 1})')
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                mark = self.peek_event().start_mark
                raise InputError('scenario', f'nested more than {MAX_DEPTH} levels deep '
                                 f'(line {mark.line + 1})')
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


def yaml_problem(error: Exception) -> str:
    """
    Say what PyYAML found wrong, and where: ``line L, column C: PROBLEM (CONTEXT at line L)``.

    PyYAML's own message spans several lines (a snippet of the file with a caret);
    this keeps its marks (1-based) and words on one line.
    """
    mark = getattr(error, 'problem_mark', None)
    problem = getattr(error, 'problem', None)
    if mark is None or not problem:
        return cut((str(error).splitlines() or [''])[0])
    text = f'line {mark.line + 1}, column {mark.column + 1}: {cut(problem)}'
    context, where = getattr(error, 'context', None), getattr(error, 'context_mark', None)
    if context:
        at = '' if where is None else f' at line {where.line + 1}, column {where.column + 1}'
        text += f' ({cut(context)}{at})'
    return text
