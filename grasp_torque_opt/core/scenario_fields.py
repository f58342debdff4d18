# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The scenario file's field readers: each checks one value and names its field.

Small pure functions shared by :func:`grasp_torque_opt.core.scenario.parse_scenario`
and its sections; every error is an :class:`InputError` naming the field and quoting
the value cut short.
"""

from __future__ import annotations

import math
from typing import Any

from grasp_torque_opt.core.coupling import Mimic
from grasp_torque_opt.core.exceptions import cut, InputError, quote
import numpy as np

#: Most joints a scenario may list (the model's size is bounded where it is loaded).
MAX_JOINTS = 64
_COUPLING_KEYS = {'follows', 'multiplier', 'offset'}


def mapping(value: Any, name: str, allowed: set[str]) -> dict:
    if not isinstance(value, dict):
        raise InputError(name, f'must be a mapping, got {type(value).__name__}')
    for key in value:
        if key not in allowed:
            raise InputError(f'{name}.{cut(key)}' if name else cut(key),
                             f"unknown field (allowed: {', '.join(sorted(allowed))})")
    return value


def require(section: dict, key: str, name: str) -> Any:
    if key not in section or section[key] is None:
        raise InputError(f'{name}.{key}' if name else key, 'missing required field')
    return section[key]


def number(value: Any, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(name, f'must be a number, got {quote(value)}')
    try:
        x = float(value)
    except OverflowError:  # an integer of more than 308 digits
        x = math.inf
    if not math.isfinite(x):
        raise InputError(name, f'must be finite, got {quote(value)}')
    return x


def vector(value: Any, name: str, length: int | None = None) -> np.ndarray:
    if not isinstance(value, (list, tuple)):
        raise InputError(name, f'must be a list of numbers, got {quote(value)}')
    if length is not None and len(value) != length:
        raise InputError(name, f'must have {length} entries, got {len(value)}')
    return np.array([number(v, f'{name}[{i}]') for i, v in enumerate(value)], dtype=float)


def positive(value: Any, name: str) -> float:
    x = number(value, name)
    if x <= 0.0:
        raise InputError(name, f'must be > 0, got {quote(value)}')
    return x


def margin(value: Any, name: str = 'friction.margin') -> float:
    """Parse a friction margin k: finite and >= 0 [-]."""
    k = number(value, name)
    if k < 0.0:
        raise InputError(name, f'must be >= 0, got {value!r}')
    return k


def names(value: Any, name: str) -> list[str]:
    if not isinstance(value, list) or not value:
        raise InputError(name, 'must be a non-empty list of names')
    if len(value) > MAX_JOINTS:
        raise InputError(name, f'{len(value)} names, more than {MAX_JOINTS}')
    out, seen = [], set()
    for i, v in enumerate(value):
        if not isinstance(v, str) or not v:
            raise InputError(f'{name}[{i}]', f'must be a name, got {quote(v)}')
        if v in seen:
            raise InputError(f'{name}[{i}]', f"duplicate name '{cut(v)}'")
        out.append(v)
        seen.add(v)
    return out


def parse_coupling(value: Any, names: dict[str, str]) -> list[Mimic]:
    """
    Validate ``hand.coupling``: joint -> {follows: joint, multiplier: k, offset: b}.

    Args:
        value: the section as parsed (None: no coupling).
        names: the scenario's name map (scenario name -> URDF name).

    Returns:
        One :class:`Mimic` per entry, URDF names (the targets resolved by the hand).
    """
    if value is None:
        return []
    if not isinstance(value, dict):
        raise InputError('hand.coupling', 'must be a mapping joint -> {follows, multiplier, '
                         f'offset}}, got {quote(value)}')
    if len(value) > MAX_JOINTS:
        raise InputError('hand.coupling', f'{len(value)} entries, more than {MAX_JOINTS}')
    out = []
    for joint, entry in value.items():
        if not isinstance(joint, str) or not joint:
            raise InputError('hand.coupling', f'a key must be a joint name, got {quote(joint)}')
        field = f'hand.coupling.{cut(joint)}'
        entry = mapping(entry, field, _COUPLING_KEYS)
        target = require(entry, 'follows', field)
        if not isinstance(target, str) or not target:
            raise InputError(f'{field}.follows', f'must be a joint name, got {quote(target)}')
        k = number(entry.get('multiplier', 1.0), f'{field}.multiplier')
        b = number(entry.get('offset', 0.0), f'{field}.offset')
        out.append(Mimic(names.get(joint, joint), names.get(target, target), k, b, field))
    return out
