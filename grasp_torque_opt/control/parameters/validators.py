# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The checks of the node's parameters: small pure functions, named in the schema.

Built-in validators are generate_parameter_library's (``bounds<>``, ``one_of<>``,
``fixed_size<>``, ``element_bounds<>``); custom ones take (parameter, value,
:class:`Context`) and give the problem in words ('' if none), or raise
:class:`~grasp_torque_opt.core.exceptions.InputError` naming an entry. Choices that a
registry holds are named, not written out (:data:`REGISTRY_CHOICES`: ``one_of_backends``
is ``one_of<>`` over the backends' registry). The ROS side adds its own (topic names) in
:mod:`grasp_torque_opt.ros.node.parameters`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
import math
from typing import Any

from grasp_torque_opt.backends.registry import available, BACKENDS
from grasp_torque_opt.control.commands.registry import COMMAND_INTERFACES
from grasp_torque_opt.control.motion import tilt_radius, uncertainty_margin
from grasp_torque_opt.control.parameters.limits import (
    MAX_GRAVITY,
    MAX_WEIGHT_RATIO,
    WEIGHT_RANGE,
)
from grasp_torque_opt.core.exceptions import cut, InputError, quote
from grasp_torque_opt.core.hand import Hand
from grasp_torque_opt.core.scenario import MAX_NAME_MAP, parse_name_map
import numpy as np


@dataclass(frozen=True)
class Context:
    """
    What some checks need beyond the value: the hand, once loaded.

    Attributes:
        m: number of actuated joints (None: no hand yet, lengths are not checked).
        joints: their names, for messages.
        torque_bounds: the largest accepted torque limit per joint [N m] (None:
            unchecked).
        scenario_object: the scenario's object (uncertainty.pose needs its radius; None: none).
    """

    m: int | None = None
    joints: tuple[str, ...] = ()
    torque_bounds: np.ndarray | None = None
    scenario_object: Any = None


#: A custom validator: (parameter, value, context) -> the problem, '' if none.
Validator = Callable[[str, Any, Context], str]


def _check_size(name: str, value: Any, n: int | None) -> str:
    if n is not None and len(value) != n:
        return f'must have {n} entries, got {len(value)}'
    return ''


def _bounds(name: str, value: Any, args: tuple, ctx: Context) -> str:
    low, high = args
    return '' if low <= value <= high else f'must be in [{low}, {high}], got {value}'


def _one_of(name: str, value: Any, args: tuple, ctx: Context) -> str:
    return '' if value in args[0] else f"must be one of {', '.join(args[0])}"


def _fixed_size(name: str, value: Any, args: tuple, ctx: Context) -> str:
    return _check_size(name, value, int(args[0]))


def _element_bounds(name: str, value: Any, args: tuple, ctx: Context) -> str:
    low, high = args
    return '' if all(low <= v <= high for v in value) else \
        f'every entry must be in [{low:g}, {high:g}]'


#: Choices that belong to a registry: validator -> the registry's names. The loader
#: makes an entry's ``one_of_backends: [[EXTRA, ...]]`` a ``one_of<>`` over the
#: registry's names and then the extra ones (``solver.fallback``'s ``none``).
REGISTRY_CHOICES: dict[str, tuple[str, ...]] = {'one_of_backends': BACKENDS,
                                                'one_of_command_interfaces': COMMAND_INTERFACES}

#: generate_parameter_library's validators that this schema uses.
BUILT_IN: dict[str, Callable[[str, Any, tuple, Context], str]] = {
    'bounds<>': _bounds, 'one_of<>': _one_of, 'fixed_size<>': _fixed_size,
    'element_bounds<>': _element_bounds,
}


def name_map_of(entries: list[str] | None) -> dict[str, str]:
    """
    Parse the ``name_map`` parameter: entries ``SCENARIO_NAME=URDF_NAME``.

    Args:
        entries: the parameter's value (None or empty: no map).

    Returns:
        scenario name -> URDF name.

    Raises:
        InputError: an entry without one ``=`` between two names, a name mapped
            twice, two names mapped to one, more than MAX_NAME_MAP entries.
    """
    if not entries:
        return {}
    if len(entries) > MAX_NAME_MAP:
        raise InputError('name_map', f'{len(entries)} entries, more than {MAX_NAME_MAP}')
    out: dict[str, str] = {}
    for i, entry in enumerate(entries):
        key, sep, target = (part.strip() for part in str(entry).partition('='))
        if not sep or not key or not target or '=' in target:
            raise InputError(f'name_map[{i}]', f'must be SCENARIO_NAME=URDF_NAME, got '
                             f'{quote(entry)}')
        if key in out:
            raise InputError(f'name_map[{i}]', f"maps '{cut(key)}' a second time")
        out[key] = target
    return parse_name_map(out, 'name_map')


# -- custom validators: small pure functions, named in the schema ---------------------------

def validate_name_map(name: str, value: Any, ctx: Context) -> str:
    """Each entry ``SCENARIO_NAME=URDF_NAME``, one to one."""
    name_map_of(value)  # raises with its own field (name_map[i]) naming the entry
    return ''


def validate_size_of_joints(name: str, value: Any, ctx: Context) -> str:
    """One entry per actuated joint (unchecked before the hand is loaded)."""
    return _check_size(name, value, ctx.m)


def validate_size_of_joints_or_empty(name: str, value: Any, ctx: Context) -> str:
    """Empty, or one entry per actuated joint."""
    return '' if len(value) == 0 else _check_size(name, value, ctx.m)


def validate_positive_entries(name: str, value: Any, ctx: Context) -> str:
    """Every entry > 0."""
    return '' if all(v > 0 for v in value) else 'every entry must be > 0'


def validate_within_urdf_limits(name: str, value: Any, ctx: Context) -> str:
    """Each torque limit at most its joint's bound (the URDF's effort limit)."""
    if ctx.torque_bounds is None:
        return ''
    Hand.check_limits(np.array(value, dtype=float), list(ctx.joints), ctx.torque_bounds,
                      name, 'torque_limits_above_urdf (read-only: at start)')
    return ''


def validate_one_or_per_joint(name: str, value: Any, ctx: Context) -> str:
    """One entry for every joint, or one per joint (unset: nothing to check)."""
    if not value or len(value) == 1 or ctx.m is None or len(value) == ctx.m:
        return ''
    return f'must have 1 entry (every joint) or {ctx.m} (one per joint), got {len(value)}'


def validate_non_negative_entries(name: str, value: Any, ctx: Context) -> str:
    """Every entry >= 0."""
    return '' if all(v >= 0 for v in value) else 'every entry must be >= 0'


def validate_weight_range(name: str, value: Any, ctx: Context) -> str:
    """Refuse a weight outside WEIGHT_RANGE, or a ratio above MAX_WEIGHT_RATIO."""
    if not value:
        return ''
    low, high = WEIGHT_RANGE
    if not all(low <= v <= high for v in value):
        return f'every entry must be in [{low:g}, {high:g}]'
    if max(value) > MAX_WEIGHT_RATIO * min(value):
        return (f'the largest entry may be at most {MAX_WEIGHT_RATIO:g} times the smallest, '
                f'got {max(value) / min(value):.3g}')
    return ''


def validate_gravity_norm(name: str, value: Any, ctx: Context) -> str:
    """Refuse a norm above MAX_GRAVITY, as on the gravity topic."""
    if math.sqrt(sum(v * v for v in value)) > MAX_GRAVITY:
        return f'norm must be at most {MAX_GRAVITY:g} m/s^2 (as on the topic)'
    return ''


def validate_ordered_pair(name: str, value: Any, ctx: Context) -> str:
    """Refuse [low, high] with low above high."""
    return '' if value[0] <= value[1] else f'low {value[0]:g} is above high {value[1]:g}'


def validate_backend_installed(name: str, value: Any, ctx: Context) -> str:
    """Refuse a backend whose Python module cannot be imported here."""
    return '' if available(value) else f'{value} is not installed (pip install {value})'


def validate_method_available(name: str, value: Any, ctx: Context) -> str:
    """tau-qp-adaptive needs DAQP."""
    if value == 'tau-qp' or available('daqp'):
        return ''
    return f'{value} needs daqp, which is not installed (pip install daqp)'


#: The custom validators that need no ROS, by the names the schema gives them.
VALIDATORS: dict[str, Validator] = {
    'name_map': validate_name_map,
    'size_of_joints': validate_size_of_joints,
    'size_of_joints_or_empty': validate_size_of_joints_or_empty,
    'positive_entries': validate_positive_entries,
    'within_urdf_limits': validate_within_urdf_limits,
    'one_or_per_joint': validate_one_or_per_joint,
    'non_negative_entries': validate_non_negative_entries,
    'weight_range': validate_weight_range,
    'gravity_norm': validate_gravity_norm,
    'ordered_pair': validate_ordered_pair,
    'backend_installed': validate_backend_installed,
    'method_available': validate_method_available,
}


def check_pairs(values: Mapping[str, Any], ctx: Context | None = None) -> None:
    """
    Check the rules between parameters (after each one's own check).

    Raises:
        InputError: gravity's norm outside gravity_norm_bounds; min-max with a method
            other than tau-qp (docs/planner.md); effort_estimation.effort_report commanded
            without a driver_stiffness; a stated uncertainty that leaves no friction, or a
            pose uncertainty without the scenario's object (with ``ctx``).
    """
    if ctx is not None and ctx.m is not None:
        stated_margin(values, ctx.scenario_object)
    gravity, bounds = values.get('gravity'), values.get('gravity_norm_bounds')
    if gravity is not None and bounds is not None:
        norm = math.sqrt(sum(v * v for v in gravity))
        if not bounds[0] <= norm <= bounds[1]:
            raise InputError('gravity', f'norm {norm:.6g} m/s^2 is outside gravity_norm_bounds '
                             f'[{bounds[0]:g}, {bounds[1]:g}] (set those to allow it, e.g. '
                             '[0.0, 15.0] for zero gravity)')
    if (values.get('effort_estimation.effort_report') == 'commanded'
            and not values.get('effort_estimation.driver_stiffness', 0.0) > 0):
        raise InputError('effort_estimation.driver_stiffness', 'must be > 0 with '
                         'effort_estimation.effort_report commanded (the position error '
                         'times it is what the efforts measure; set it first)')
    if values.get('objective') == 'min-max' and values.get('solver.method') != 'tau-qp':
        raise InputError('objective', 'min-max needs solver.method tau-qp, not '
                         f"{values.get('solver.method')}")


def stated_margin(values: Mapping[str, Any], obj: Any) -> float | None:
    """
    Return the friction margin the stated uncertainty asks (None: none stated).

    Raises:
        InputError: the uncertainty leaves no friction, or uncertainty.pose without the
            scenario's object.
    """
    friction = values.get('uncertainty.friction') or 0.0
    pose = values.get('uncertainty.pose') or 0.0
    if friction <= 0.0 and pose <= 0.0:
        return None
    radius = tilt_radius(obj, values.get('uncertainty.tip_radius') or 0.0) if pose > 0.0 \
        else math.inf
    return uncertainty_margin(float(values.get('mu_tangential')), friction, pose, radius)
