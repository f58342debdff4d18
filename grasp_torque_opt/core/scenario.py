# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Scenario files (YAML, schema in docs/design.md section 4): load and validate.

Validation here is structural (types, lengths, finiteness, ranges); what needs
the model (joint and frame names, URDF limits) is checked when the scenario is
bound to a hand in :mod:`grasp_torque_opt.core.grasp_setup`. Every error names the
field, e.g. ``grasp.contacts[1].normal: must not be zero``, and quotes the input
cut short.

A file is read within bounds (docs/design.md section 4.1): a regular file of at
most :data:`MAX_SCENARIO_BYTES`, UTF-8, YAML without aliases and nested at most
:data:`MAX_DEPTH` deep, at most :data:`MAX_CONTACTS` contacts and
:data:`MAX_JOINTS` joints, so that a hostile file costs bounded time and memory
(a 2.8 KB alias bomb took over 4 GB; so did /dev/zero).

Names: a scenario may name its joints and links as another URDF of the same hand
does; ``hand.name_map`` (and the node's ``name_map`` parameter, merged over it) maps
them to the URDF's names before anything is checked against the model
(:func:`parse_name_map`, docs/design.md section 4.1).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from grasp_torque_opt.core.bounded_yaml import BoundedLoader, yaml_problem
from grasp_torque_opt.core.coupling import Mimic
from grasp_torque_opt.core.exceptions import cut, InputError, PATH_LENGTH, quote
from grasp_torque_opt.core.resources import decode_utf8, read_bounded
from grasp_torque_opt.core.scenario_fields import (
    AUTO,
    ContactSpec,
    DEFAULT_CONTACT_TOLERANCE,
    mapping as _mapping,
    margin as _margin,
    MAX_JOINTS,
    names as _names,
    number as _number,
    parse_contacts,
    parse_coupling,
    positive as _positive,
    require as _require,
    vector as _vector,
)
import numpy as np
import yaml

#: Largest scenario file read [bytes] (the bundled ones are about 2 KB).
MAX_SCENARIO_BYTES = 256 * 1024
#: Most contacts of a scenario (1000 took over 4 GB in the QP's dense matrices).
MAX_CONTACTS = 32
#: Most sides of the friction polygon (the node's parameter has the same range; the QP
#: grows with it: 2N rows per contact).
MAX_POLYGON_SIDES = 64
#: Most entries of a name map (a URDF has at most 512 joints and 512 links).
MAX_NAME_MAP = 1024


@dataclass(frozen=True)
class Friction:
    """
    Soft-finger friction and its linearization.

    Attributes:
        mu1: tangential friction coefficient [-].
        mu2: torsional friction coefficient [m].
        sides: number of sides N of the inscribed polygon (N >= 3).
        min_normal_force: lower bound on every normal force [N].
        margin: friction margin k >= 0 [-]: plan inside the cone of mu1/(1+k),
            mu2/(1+k) (:func:`grasp_torque_opt.core.margin.planned_friction`).
    """

    mu1: float
    mu2: float
    sides: int
    min_normal_force: float = 0.0
    margin: float = 0.0


#: Objectives of the tau-QP (docs/planner.md): the paper's sum of squared torques, and
#: the min-max of |tau_i| / limit_i (an LP, then the sum of squares among its optima).
OBJECTIVES = ('sum-of-squares', 'min-max')

#: Object shapes and the entries of their ``size`` [m].
SHAPES = {'sphere': ('radius',), 'box': ('x', 'y', 'z'), 'cylinder': ('radius', 'length')}


@dataclass(frozen=True)
class ObjectSpec:
    """
    The grasped object: what a simulation holds, and whose weight can be the load.

    Attributes:
        shape: ``sphere``, ``box`` or ``cylinder`` (axis along the object's z).
        size: sphere [radius], box [x, y, z] edge lengths, cylinder [radius,
            length] [m].
        mass: [kg], > 0; uniform density, so the centre of mass is ``position``.
        position: the shape's centre in the base frame [m], shape (3,); default
            ``grasp.object_origin``.
        rpy: orientation, roll-pitch-yaw about the fixed base x, y, z axes (as a
            URDF origin) [rad], shape (3,).
    """

    shape: str
    size: np.ndarray
    mass: float
    position: np.ndarray
    rpy: np.ndarray


@dataclass(frozen=True)
class Scenario:
    """
    A validated scenario.

    Attributes:
        urdf: the hand's URDF path as written (see :func:`resolve_urdf`).
        base_dir: folder of the scenario file, for relative URDF paths.
        joints: actuated joints in command order, or None for all 1-DoF joints.
        torque_limits: |tau_i| bound [N m], a scalar, a list, or None (URDF effort).
        joint_positions: joint name -> position [rad or m].
        object_origin: object origin c in the base frame [m], shape (3,).
        contacts: the contacts as written; a contact given by its link only (with an
            ``object``) has ``position`` None: found from geometry when bound
            (:mod:`grasp_torque_opt.core.scenario_contacts`). Empty with ``contacts: auto``.
        friction: friction model.
        external_wrench: load on the object about c, base axes, shape (6,) [N, N m]:
            the object's weight (with ``object`` and ``gravity``) plus ``extra_wrench``.
        weights: objective weights per joint, or None for ones.
        object: the object, or None.
        gravity: gravity in the base frame [m/s^2], shape (3,), or None: drives the
            object's weight and the node's default g(q) (docs/design.md section 4).
        extra_wrench: ``load.external_wrench`` as written: the load besides the
            object's weight, shape (6,) [N, N m].
        torque_limits_above_urdf: allow torque limits above the URDF's effort limits.
        name_map: the map applied to the scenario's joint and frame names (scenario
            name -> URDF name; ``hand.name_map`` with the caller's entries over it):
            ``joints``, ``joint_positions`` and the contacts' links are already the
            URDF's names.
        coupling: ``hand.coupling``: coupled joints besides the URDF's mimic tags.
        base_link: ``hand.base_link``: the frame the grasp, gravity and load are
            written in, or None for the model's root link.
        contacts_auto: ``contacts: auto``: every link within the tolerance of the object.
        contact_tolerance: ``grasp.contact_tolerance`` [m]: a link within it of the
            object touches it; a point written by hand farther is warned about.
    """

    urdf: str
    base_dir: Path
    joints: list[str] | None
    torque_limits: float | list[float] | None
    joint_positions: dict[str, float]
    object_origin: np.ndarray
    contacts: list[ContactSpec]
    friction: Friction
    external_wrench: np.ndarray
    weights: list[float] | None = None
    source: str = field(default='<memory>')
    object: ObjectSpec | None = None  # noqa: A003 -- the scenario's object section, by name
    gravity: np.ndarray | None = None
    extra_wrench: np.ndarray = field(default_factory=lambda: np.zeros(6))
    objective: str = 'sum-of-squares'
    torque_limits_above_urdf: bool = False
    name_map: dict[str, str] = field(default_factory=dict)
    coupling: list[Mimic] = field(default_factory=list)
    base_link: str | None = None
    contacts_auto: bool = False
    contact_tolerance: float = DEFAULT_CONTACT_TOLERANCE


def weight_wrench(obj: ObjectSpec | None, gravity: np.ndarray | None,
                  origin: np.ndarray) -> np.ndarray:
    """
    Return the object's weight as a wrench about ``origin``, base axes [N, N m], shape (6,).

    Zero without an object or without gravity.
    """
    if obj is None or gravity is None:
        return np.zeros(6)
    force = obj.mass * np.asarray(gravity, dtype=float)
    return np.concatenate((force, np.cross(obj.position - origin, force)))


_SECTIONS = {
    'hand': {'urdf', 'joints', 'torque_limits', 'torque_limits_above_urdf', 'name_map',
             'coupling', 'base_link'},
    'grasp': {'joint_positions', 'object_origin', 'contacts', 'contact_tolerance'},
    'friction': {'mu_tangential', 'mu_torsional', 'polygon_sides', 'min_normal_force',
                 'margin'},
    'load': {'external_wrench'},
    'objective': {'weights', 'type'},
}
_OBJECT_KEYS = {'shape', 'size', 'mass', 'position', 'rpy'}


def _object(value: Any, origin: np.ndarray) -> ObjectSpec:
    section = _mapping(value, 'object', _OBJECT_KEYS)
    shape = _require(section, 'shape', 'object')
    if shape not in SHAPES:
        raise InputError('object.shape', f"must be one of {', '.join(SHAPES)}, got {shape!r}")
    entries = SHAPES[shape]
    size = _vector(_require(section, 'size', 'object'), 'object.size')
    if len(size) != len(entries):
        raise InputError('object.size', f'must have {len(entries)} entries for a {shape} '
                         f"({', '.join(entries)}), got {len(size)}")
    for i, x in enumerate(size):
        if x <= 0.0:
            raise InputError(f'object.size[{i}]', f'must be > 0, got {x}')
    mass = _positive(_require(section, 'mass', 'object'), 'object.mass')
    position = (_vector(section['position'], 'object.position', 3)
                if section.get('position') is not None else origin.copy())
    rpy = (_vector(section['rpy'], 'object.rpy', 3) if section.get('rpy') is not None
           else np.zeros(3))
    return ObjectSpec(shape=shape, size=size, mass=mass, position=position, rpy=rpy)


def parse_name_map(value: Any, name: str = 'hand.name_map') -> dict[str, str]:
    """
    Validate a name map: scenario name -> URDF name.

    Args:
        value: a mapping of names to names (None: no map).
        name: the field, for messages.

    Returns:
        The map (empty for None).

    Raises:
        InputError: not a mapping of non-empty names, more than :data:`MAX_NAME_MAP`
            entries, or two names mapped to one.
    """
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise InputError(name, f'must be a mapping scenario name -> URDF name, got '
                         f'{quote(value)}')
    if len(value) > MAX_NAME_MAP:
        raise InputError(name, f'{len(value)} entries, more than {MAX_NAME_MAP}')
    out: dict[str, str] = {}
    seen: dict[str, str] = {}
    for key, target in value.items():
        if not isinstance(key, str) or not key:
            raise InputError(name, f'a key must be a name, got {quote(key)}')
        if not isinstance(target, str) or not target:
            raise InputError(f'{name}.{cut(key)}', f'must be a name, got {quote(target)}')
        if target in seen:
            raise InputError(f'{name}.{cut(key)}', f"maps to '{cut(target)}', as "
                             f"'{cut(seen[target])}' does: two names cannot map to one")
        seen[target] = key
        out[key] = target
    return out


def _renamed(names: list[str], name_map: dict[str, str], field_name: str) -> list[str]:
    """Map names through the name map; they must stay unique (two may not become one)."""
    out = [name_map.get(n, n) for n in names]
    if len(set(out)) != len(out):
        j = next(j for j, n in enumerate(out) if out.index(n) != j)
        i = out.index(out[j])
        if names[i] == out[i]:  # name the entry the map renamed
            i, j = j, i
        other = 'is' if names[j] == out[j] else f"'{cut(names[j])}' becomes too"
        raise InputError(f'{field_name}[{i}]', f"'{cut(names[i])}' becomes '{cut(out[i])}' "
                         f'through the name map, which [{j}] {other}')
    return out


def parse_scenario(data: Any, base_dir: Path, source: str = '<memory>',
                   name_map: dict[str, str] | None = None) -> Scenario:
    """
    Validate a scenario given as plain data (as parsed from YAML).

    Args:
        data: the parsed document.
        base_dir: folder that relative URDF paths are relative to.
        source: where the data came from, for messages.
        name_map: scenario name -> URDF name, over the file's ``hand.name_map``
            (e.g. the node's ``name_map`` parameter), validated by the caller.

    Returns:
        The validated scenario.

    Raises:
        InputError: naming the first invalid field.
    """
    top = _mapping(data, '', set(_SECTIONS) | {'object', 'gravity'})
    hand = _mapping(_require(top, 'hand', ''), 'hand', _SECTIONS['hand'])
    grasp = _mapping(_require(top, 'grasp', ''), 'grasp',
                     _SECTIONS['grasp'])
    friction = _mapping(_require(top, 'friction', ''), 'friction',
                        _SECTIONS['friction'])
    gravity = _vector(top['gravity'], 'gravity', 3) if top.get('gravity') is not None else None
    # With an object and gravity the load is the object's weight; load is then optional.
    weighed = gravity is not None and top.get('object') is not None
    load = _mapping(top.get('load') or {} if weighed else _require(top, 'load', ''), 'load',
                    _SECTIONS['load'])
    objective = _mapping(top.get('objective') or {}, 'objective', _SECTIONS['objective'])

    h = _parse_hand(hand, name_map)
    names, joints = h['name_map'], h['joints']
    positions = _parse_joint_positions(grasp, names)
    origin = _vector(_require(grasp, 'object_origin', 'grasp'), 'grasp.object_origin', 3)
    contacts = parse_contacts(_require(grasp, 'contacts', 'grasp'), names,
                              top.get('object') is not None, MAX_CONTACTS)
    tolerance = _positive(grasp.get('contact_tolerance', DEFAULT_CONTACT_TOLERANCE),
                          'grasp.contact_tolerance')
    fric = _parse_friction(friction)

    if weighed and load.get('external_wrench') is None:
        extra = np.zeros(6)
    else:
        extra = _vector(_require(load, 'external_wrench', 'load'), 'load.external_wrench', 6)
    obj = _object(top['object'], origin) if top.get('object') is not None else None
    wrench = extra + weight_wrench(obj, gravity, origin)

    weights, kind = _parse_objective(objective, joints, h['torque_limits'])
    return Scenario(base_dir=base_dir, joint_positions=positions, object_origin=origin,
                    contacts=[] if contacts == AUTO else contacts,
                    friction=fric, external_wrench=wrench, weights=weights, source=source,
                    contacts_auto=contacts == AUTO, contact_tolerance=tolerance,
                    object=obj, gravity=gravity, extra_wrench=extra, objective=kind, **h)


def _parse_hand(hand: dict, name_map: dict[str, str] | None) -> dict[str, Any]:
    """Read the ``hand`` section: the Scenario's fields it gives, by name (``name_map`` merged)."""
    urdf = _require(hand, 'urdf', 'hand')
    if not isinstance(urdf, str) or not urdf:
        raise InputError('hand.urdf', f'must be a path, got {quote(urdf)}')
    names = {**parse_name_map(hand.get('name_map')), **(name_map or {})}
    if name_map:  # the merged map must be one to one as well
        names = parse_name_map(names, 'name_map')
    joints = _names(hand['joints'], 'hand.joints') if hand.get('joints') is not None else None
    if joints is not None:
        joints = _renamed(joints, names, 'hand.joints')
    limits = _parse_torque_limits(hand.get('torque_limits'), joints)
    coupling = parse_coupling(hand.get('coupling'), names)
    base_link = hand.get('base_link')
    if base_link is not None:
        if not isinstance(base_link, str) or not base_link:
            raise InputError('hand.base_link', f'must be a frame name, got {quote(base_link)}')
        base_link = names.get(base_link, base_link)
    above_urdf = hand.get('torque_limits_above_urdf', False)
    if not isinstance(above_urdf, bool):
        raise InputError('hand.torque_limits_above_urdf', 'must be true or false')
    return {'urdf': urdf, 'joints': joints, 'torque_limits': limits,
            'torque_limits_above_urdf': above_urdf, 'name_map': names, 'coupling': coupling,
            'base_link': base_link}


def _parse_torque_limits(limits: Any, joints: list[str] | None) -> float | list[float] | None:
    """Read ``hand.torque_limits``: None, one positive value, or one per joint."""
    if limits is None:
        return None
    if isinstance(limits, (list, tuple)):
        limits = [_positive(v, f'hand.torque_limits[{i}]') for i, v in enumerate(limits)]
        if joints is not None and len(limits) != len(joints):
            raise InputError('hand.torque_limits',
                             f'must have {len(joints)} entries (one per joint), '
                             f'got {len(limits)}')
        return limits
    return _positive(limits, 'hand.torque_limits')


def _parse_joint_positions(grasp: dict, names: dict[str, str]) -> dict[str, float]:
    """Read ``grasp.joint_positions``, renamed through the name map."""
    positions_raw = grasp.get('joint_positions') or {}
    if not isinstance(positions_raw, dict):
        raise InputError('grasp.joint_positions', 'must be a mapping joint name -> position')
    if len(positions_raw) > MAX_JOINTS:
        raise InputError('grasp.joint_positions',
                         f'{len(positions_raw)} entries, more than {MAX_JOINTS}')
    positions = {str(k): _number(v, f'grasp.joint_positions.{cut(k)}')
                 for k, v in positions_raw.items()}
    renamed = _renamed(list(positions), names, 'grasp.joint_positions')
    return dict(zip(renamed, positions.values()))


def _parse_friction(friction: dict) -> Friction:
    """Read the ``friction`` section."""
    sides = _require(friction, 'polygon_sides', 'friction')
    if isinstance(sides, bool) or not isinstance(sides, int):
        raise InputError('friction.polygon_sides', f'must be an integer, got {quote(sides)}')
    if sides < 3:
        raise InputError('friction.polygon_sides', f'must be >= 3, got {sides}')
    if sides > MAX_POLYGON_SIDES:
        raise InputError('friction.polygon_sides',
                         f'must be at most {MAX_POLYGON_SIDES}, got {quote(sides)}')
    fmin = _number(friction.get('min_normal_force', 0.0), 'friction.min_normal_force')
    if fmin < 0.0:
        raise InputError('friction.min_normal_force', f'must be >= 0, got {fmin}')
    return Friction(
        mu1=_positive(_require(friction, 'mu_tangential', 'friction'), 'friction.mu_tangential'),
        mu2=_positive(_require(friction, 'mu_torsional', 'friction'), 'friction.mu_torsional'),
        sides=sides,
        min_normal_force=fmin,
        margin=_margin(friction.get('margin', 0.0)),
    )


def _parse_objective(objective: dict, joints: list[str] | None,
                     limits: float | list[float] | None) -> tuple[list[float] | None, str]:
    """Read the ``objective`` section: (weights, type); per-joint values need ``hand.joints``."""
    weights = None
    if objective.get('weights') is not None:
        weights = [_positive(v, f'objective.weights[{i}]')
                   for i, v in enumerate(_vector(objective['weights'], 'objective.weights'))]
        if joints is not None and len(weights) != len(joints):
            raise InputError('objective.weights',
                             f'must have {len(joints)} entries (one per joint), '
                             f'got {len(weights)}')

    kind = objective.get('type', OBJECTIVES[0])
    if kind not in OBJECTIVES:
        raise InputError('objective.type', f"must be one of {', '.join(OBJECTIVES)}, "
                         f'got {kind!r}')
    if joints is None and (isinstance(limits, list) or weights is not None):
        per_joint = 'hand.torque_limits' if isinstance(limits, list) else 'objective.weights'
        raise InputError('hand.joints', f'required when {per_joint} gives one value per joint '
                         "(without it the values would follow Pinocchio's joint order, which "
                         "is not the URDF file's: on the Allegro 0-3, 12-15, 4-7, 8-11)")
    return weights, kind


def load_scenario(path: str | Path, name_map: dict[str, str] | None = None) -> Scenario:
    """
    Read and validate a scenario file, within the bounds of the module's docstring.

    ``name_map`` (scenario name -> URDF name) goes over the file's ``hand.name_map``.

    Raises:
        InputError: the file cannot be read, is not a regular file, too large, not
            UTF-8, not valid or bounded YAML (field ``scenario``), or a field is
            invalid (named).
    """
    path = Path(path)
    text = decode_utf8(read_bounded(path, 'scenario', MAX_SCENARIO_BYTES), path, 'scenario')
    try:
        data = yaml.load(text, Loader=BoundedLoader)  # noqa: S506 -- a SafeLoader
    except (yaml.YAMLError, ValueError) as e:  # ValueError: an integer of 5000 digits
        raise InputError('scenario', f'{cut(path, PATH_LENGTH)} is not valid YAML: '
                         f'{yaml_problem(e)}') from e
    return parse_scenario(data, path.resolve().parent, source=str(path), name_map=name_map)
