# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The adversarial campaign's tools: generated messages, invariants and counts.

The messages are generated from their definitions, the invariants are those every
published command must meet, and the counts are printed after the run.

Strategies start from a valid message and overwrite some of its fields, each chosen
among the leaf fields that ``get_fields_and_field_types`` lists and filled with a value
of that field's type (NaN, Inf, huge, empty and oversized sequences, unknown and
duplicate names, zero and non-unit quaternions), so that the messages reach every
check and, often enough, the solver.
"""

from __future__ import annotations

import copy
import importlib

from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
import numpy as np

#: Counts of the whole run, printed by conftest's terminal summary.
COUNTS = {'inputs': 0, 'commands': 0, 'broken': 0, 'pulling': 0, 'chattering': 0, 'late': 0}

#: Reproducible and bounded: CI sees the same examples every run.
CAMPAIGN = settings(deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.function_scoped_fixture])

#: Stands for "this sequence, 100000 entries long" (a huge message).
OVERSIZED = object()

FLOATS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.sampled_from([0.0, -0.0, np.nan, np.inf, -np.inf, 1e308, -1e308, 5e-324, 1e6, -1e6]),
    st.floats(-2.0, 2.0))


def message_class(type_name: str):
    """Return the Python class of a ROS type such as ``geometry_msgs/Pose``."""
    package, name = type_name.split('/')
    return getattr(importlib.import_module(f'{package}.msg'), name)


def leaf_fields(cls, prefix: str = '') -> list[tuple[str, str]]:
    """
    Return (dotted path, type) of every leaf field of a message class, from its definition.

    Sequences of messages are leaves (their length and content are generated whole).
    """
    out = []
    for name, typ in cls.get_fields_and_field_types().items():
        path = f'{prefix}{name}'
        if '/' in typ and not typ.startswith('sequence<'):
            out += leaf_fields(message_class(typ), path + '.')
        else:
            out.append((path, typ))
    return out


def value_of(typ: str, names: list[str], max_len: int = 12) -> st.SearchStrategy:
    """Values of a ROS field type, valid and invalid."""
    if typ in ('double', 'float'):
        return FLOATS
    if typ == 'int32':
        return st.one_of(st.integers(-2**31, 2**31 - 1), st.sampled_from([0, -1, 2**31 - 1]))
    if typ == 'uint32':
        return st.one_of(st.integers(0, 2**32 - 1), st.just(0))
    if typ == 'string':
        return st.one_of(st.sampled_from(names + ['', 'no_such_frame', 'x' * 5000]),
                         st.text(max_size=12))
    if typ.startswith('sequence<'):
        inner = typ[len('sequence<'):-1]
        item = messages_of(message_class(inner), names) if '/' in inner else \
            value_of(inner, names)
        return st.one_of(st.lists(item, max_size=max_len), st.just(OVERSIZED))
    raise NotImplementedError(typ)


def messages_of(cls, names: list[str]) -> st.SearchStrategy:
    """Messages of a class with every leaf field generated."""
    leaves = leaf_fields(cls)

    @st.composite
    def build(draw):
        msg = cls()
        for path, typ in leaves:
            set_field(msg, path, draw(value_of(typ, names)))
        return msg
    return build()


def set_field(msg, path: str, value) -> None:
    """Set a dotted field; :data:`OVERSIZED` fills a sequence with 100000 default items."""
    *parents, last = path.split('.')
    target = msg
    for p in parents:
        target = getattr(target, p)
    if value is OVERSIZED:
        item = type(getattr(target, last)[0])() if len(getattr(target, last)) else 0.0
        value = [item] * 100000
    try:
        setattr(target, last, value)
    except (AssertionError, TypeError, ValueError):
        pass  # the message type refuses it (e.g. a str in a double): never on the wire


@st.composite
def mutated(draw, valid, names: list[str], max_mutations: int = 3):
    """Draw a copy of a valid message with up to ``max_mutations`` leaf fields regenerated."""
    msg = copy.deepcopy(valid)
    leaves = leaf_fields(type(valid))
    for _ in range(draw(st.integers(0, max_mutations))):
        path, typ = draw(st.sampled_from(leaves))
        items = getattr(msg, path) if '.' not in path else None
        if typ.startswith('sequence<') and '/' in typ and items and draw(st.booleans()):
            # One field of one item, e.g. poses[1].orientation.w.
            item = items[draw(st.integers(0, len(items) - 1))]
            sub, sub_typ = draw(st.sampled_from(leaf_fields(type(item))))
            set_field(item, sub, draw(value_of(sub_typ, names)))
        else:
            set_field(msg, path, draw(value_of(typ, names)))
    return msg


def check_command(cmd, m: int, limits: np.ndarray) -> None:
    """Check the invariant on what reaches the motors: len(joints) finite values within limits."""
    COUNTS['commands'] += 1
    cmd = np.asarray(cmd, dtype=float)
    ok = cmd.shape == (m,) and bool(np.all(np.isfinite(cmd))) and \
        bool(np.all(np.abs(cmd) <= limits))
    if not ok:
        COUNTS['broken'] += 1
    assert ok, f'command broke the invariant: {cmd!r}'


def broken(why: str) -> None:
    """Count a broken invariant and fail."""
    COUNTS['broken'] += 1
    raise AssertionError(why)
