# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The parameters' frozen snapshot made and read by dotted name, and its cycle settings.

The classes are generated (:mod:`~grasp_torque_opt.control.parameters.generated`); these
functions are written by hand, once, and work on any of them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import fields, is_dataclass
from typing import Any

from grasp_torque_opt.control.parameters.generated import CYCLE_FIELDS, CycleConfig, Params


def params_from(values: Mapping[str, Any], cls: type = Params, prefix: str = '') -> Any:
    """
    Make the frozen snapshot of every value (a list becomes a tuple).

    Args:
        values: dotted name -> value (a missing or None value: None).
        cls: the class to make (a namespace's, for its ``prefix``).
        prefix: the namespace's dotted prefix (``solver.``).
    """
    kwargs = {}
    for f in fields(cls):
        if is_dataclass(f.type):
            kwargs[f.name] = params_from(values, f.type, f'{prefix}{f.name}.')
        else:
            value = values.get(f'{prefix}{f.name}')
            kwargs[f.name] = tuple(value) if isinstance(value, list) else value
    return cls(**kwargs)


def value_of(p: Params, name: str) -> Any:
    """Give one value of a :class:`Params` snapshot by its dotted name (``imu.enabled``)."""
    value = p
    for part in name.split('.'):
        value = getattr(value, part)
    return value


def cycle_config(p: Params) -> CycleConfig:
    """Make the :class:`CycleConfig` of a :class:`Params` snapshot."""
    return CycleConfig(**{field: value_of(p, name) for field, name in CYCLE_FIELDS.items()})
