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

from dataclasses import dataclass
import math
from typing import Any

from grasp_torque_opt.core.coupling import Mimic
from grasp_torque_opt.core.exceptions import cut, InputError, quote
import numpy as np

#: Most joints a scenario may list (the model's size is bounded where it is loaded).
MAX_JOINTS = 64
_COUPLING_KEYS = {'follows', 'multiplier', 'offset'}
_CONTACT_KEYS = {'link', 'position', 'normal', 'tangent'}
#: ``grasp.contacts: auto``: every link within the tolerance of the object.
AUTO = 'auto'
#: Default ``grasp.contact_tolerance`` [m].
DEFAULT_CONTACT_TOLERANCE = 1e-3


@dataclass(frozen=True)
class ContactSpec:
    """
    One contact as the scenario states it.

    Attributes:
        link: model frame that touches the object.
        position: contact point in that frame [m], shape (3,); None in a scenario for
            "found from geometry" (a link only, with an ``object``), never once bound.
        normal: inward unit normal in base axes, shape (3,), or None for
            "from the contact point towards the object origin".
        tangent: x axis of the contact frame in base axes, shape (3,), or None
            for the pinned tangent rule.
    """

    link: str
    position: np.ndarray | None
    normal: np.ndarray | None = None
    tangent: np.ndarray | None = None


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


def parse_contacts(value: Any, names: dict[str, str], has_object: bool, most: int
                   ) -> list[ContactSpec] | str:
    """
    Validate ``grasp.contacts``: a list of contacts, or ``auto`` (with an object).

    A contact given by its link only (no ``position``, no ``normal``; a ``tangent``
    may be given) is found from geometry when the scenario has an ``object``; else, as
    always, a missing position is the link's origin.

    Args:
        value: the field as parsed.
        names: the scenario's name map.
        has_object: the scenario has an ``object`` section.
        most: the most contacts allowed.

    Returns:
        The contacts, or :data:`AUTO`.
    """
    if value == AUTO:
        if not has_object:
            raise InputError('grasp.contacts', "'auto' needs the object section (the contacts "
                             "are found from the hand's collision shapes and the object)")
        return AUTO
    if not isinstance(value, list) or not value:
        raise InputError('grasp.contacts', "must be a non-empty list of contacts or 'auto'")
    if len(value) > most:
        raise InputError('grasp.contacts', f'{len(value)} contacts, more than {most}')
    contacts = []
    for i, c in enumerate(value):
        name = f'grasp.contacts[{i}]'
        c = mapping(c, name, _CONTACT_KEYS)
        link = require(c, 'link', name)
        if not isinstance(link, str) or not link:
            raise InputError(f'{name}.link', f'must be a frame name, got {quote(link)}')
        found = has_object and c.get('position') is None and c.get('normal') is None
        position = (None if found else vector(c['position'], f'{name}.position', 3)
                    if c.get('position') is not None else np.zeros(3))
        normal = None
        if c.get('normal') is not None:
            normal = vector(c['normal'], f'{name}.normal', 3)
            norm = np.linalg.norm(normal)
            if norm < 1e-9:
                raise InputError(f'{name}.normal', 'must not be zero')
            normal = normal / norm
        tangent = None
        if c.get('tangent') is not None:
            tangent = vector(c['tangent'], f'{name}.tangent', 3)
            if np.linalg.norm(tangent) < 1e-9:
                raise InputError(f'{name}.tangent', 'must not be zero')
            if normal is not None:
                t = tangent / np.linalg.norm(tangent)
                if np.linalg.norm(t - (t @ normal) * normal) < 1e-6:
                    raise InputError(f'{name}.tangent', 'is parallel to the normal')
        contacts.append(ContactSpec(link=names.get(link, link), position=position,
                                    normal=normal, tangent=tangent))
    return contacts
