# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Candidate grasps from geometry: the object placed near the palm, the fingers on it.

:func:`plan_grasps` draws, from one seed, an object pose in a reach region about the
base scenario's object origin (a box's or cylinder's orientation opposed to the base
grasp's thumb and fingers, :func:`opposition_frame`, slightly tilted; or uniform at
random, always for a mesh) and joint positions about the base scenario's grasp, then
solves the IK of :mod:`~grasp_torque_opt.methods.plan_ik` (the contact links'
collision shapes on the object's surface, every other shape at least ``clearance``
from it, joints within their limits). A solution is kept only if an independent
check passes: the contacts found by
:class:`~grasp_torque_opt.core.geometry_contacts.GeometryContacts` (closed forms
where they apply) are every contact link's, each within ``tolerance`` of the
surface with its inward normal, none within :data:`EDGE` of an edge; every other
link of the hand (the palm included) is at least ``clearance`` away; every joint is
within its URDF limits. Then, by default, it must hold its own load: its load
capacity (:mod:`.capacity`, certified, every load from zero up to it held) with
friction margin ``hold_margin`` is at least 1. Each refusal is counted by its reason.
Each candidate is a line that ``grasp-torque-opt score`` reads (docs/planner.md,
"Planning candidates").
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
import json
import math
from pathlib import Path
from typing import Any

import coal
from grasp_torque_opt.core.exceptions import GeometryError, InputError
from grasp_torque_opt.core.geometry_contacts import collision_model, GeometryContacts, hand_links
from grasp_torque_opt.core.grasp_setup import bind_for_candidates
from grasp_torque_opt.core.hand import resolve_urdf
from grasp_torque_opt.core.object_geometry import ObjectShape
from grasp_torque_opt.core.scenario import load_scenario, Scenario
from grasp_torque_opt.methods.capacity import load_capacity
from grasp_torque_opt.methods.plan_ik import SurfaceIK
import numpy as np
import pinocchio as pin

#: Most candidates one call plans.
MAX_COUNT = 100_000
#: A contact this close to a box's edge or a cylinder's rim is refused [m].
EDGE = 3e-3
#: Contact modes of the output: points and normals written, or the links only.
CONTACT_MODES = ('points', 'links')
#: How a box's or cylinder's orientation is drawn (docs/planner.md, "Planning candidates").
ORIENTATIONS = ('opposed', 'random')
#: Whose collision shapes the planner reads (PlanSettings.shapes).
SHAPES = ('hand', 'robot')
#: Standard deviation of the tilt about the opposed orientation [rad].
TILT = 0.1
#: The friction margin a kept candidate's own load is held at, by default [-].
HOLD_MARGIN = 0.3


@dataclass(frozen=True)
class PlanSettings:
    """
    What to plan.

    Attributes:
        count: candidates wanted.
        seed: the seed of every draw (same seed, same candidates).
        links: the contact links; None: the base scenario's contacts' links.
        region: half the edge of the cube the object's centre is drawn in and kept in,
            about ``centre`` [m].
        centre: the region's centre, base frame [m]; None: the base's object origin.
        rotate: draw the object's orientation (a sphere's is never drawn).
        orientation: ``opposed`` (a box's faces, a cylinder's side, facing the base
            grasp's fingers and thumb, tilted at random) or ``random`` (uniform).
        hold_margin: keep only candidates that hold their own load from zero with this
            friction margin (or the scenario's, if larger) [-]; None keeps every
            candidate that touches.
        joint_spread: standard deviation of the start joints about the base grasp [rad].
        clearance: every other link keeps at least this from the object [m].
        tolerance: a contact link within this of the surface (either side) [m].
        joint_margin: the IK keeps the joints this far inside their limits [rad].
        attempts: IKs at most per candidate wanted.
        contacts: ``points`` (each contact's point and normal written) or ``links``
            (the link only: ``score`` finds them from geometry).
        extra_load: a wrench added to the object's weight [N, N m], or None.
        shapes: whose collision shapes the IK keeps clear of the object and the check
            reads: ``hand`` (the hand's own links, :func:`hand_links`, and the contact
            links: the rest of a robot's URDF is not read) or ``robot`` (every link of
            the URDF, a G1's legs and torso too).
    """

    count: int = 10
    seed: int = 0
    links: tuple[str, ...] | None = None
    region: float = 0.02
    centre: tuple[float, float, float] | None = None
    rotate: bool = True
    orientation: str = 'opposed'
    hold_margin: float | None = HOLD_MARGIN
    joint_spread: float = 0.2
    clearance: float = 2e-3
    tolerance: float = 5e-4
    joint_margin: float = 0.02
    attempts: int = 50
    contacts: str = 'points'
    extra_load: tuple[float, ...] | None = None
    shapes: str = 'hand'

    def __post_init__(self) -> None:
        """Refuse a setting out of its range, naming it."""
        if not (isinstance(self.count, int) and 1 <= self.count <= MAX_COUNT):
            raise InputError('count', f'must be an integer in [1, {MAX_COUNT}], got '
                             f'{self.count!r}')
        for name in ('region', 'clearance', 'tolerance'):
            value = getattr(self, name)
            if not (math.isfinite(value) and 0.0 < value <= 1.0):
                raise InputError(name, f'must be in (0, 1] m, got {value!r}')
        for name in ('joint_spread', 'joint_margin'):
            value = getattr(self, name)
            if not (math.isfinite(value) and 0.0 <= value <= 10.0):
                raise InputError(name, f'must be in [0, 10] rad, got {value!r}')
        if not (isinstance(self.attempts, int) and 1 <= self.attempts <= 1000):
            raise InputError('attempts', f'must be an integer in [1, 1000], got '
                             f'{self.attempts!r}')
        if self.shapes not in SHAPES:
            raise InputError('shapes', f"must be one of {', '.join(SHAPES)}, got "
                             f'{self.shapes!r}')
        if self.orientation not in ORIENTATIONS:
            raise InputError('orientation', f"must be one of {', '.join(ORIENTATIONS)}, got "
                             f'{self.orientation!r}')
        if self.hold_margin is not None and not (
                math.isfinite(self.hold_margin) and 0.0 <= self.hold_margin <= 100.0):
            raise InputError('hold_margin', f'must be in [0, 100], got '
                             f'{self.hold_margin!r}')
        if self.contacts not in CONTACT_MODES:
            raise InputError('contacts', f"must be one of {', '.join(CONTACT_MODES)}, got "
                             f'{self.contacts!r}')
        if self.extra_load is not None and (len(self.extra_load) != 6 or not all(
                math.isfinite(v) for v in self.extra_load)):
            raise InputError('load', f'must be 6 finite numbers, got {self.extra_load!r}')


@dataclass
class PlanResult:
    """
    The candidates (score's JSON objects), how many IKs it took, and what was asked.

    Attributes:
        candidates: the lines found, as dicts.
        attempts: the IKs run.
        settings: the settings it planned with (how many wanted, the seed).
        rejected: why IKs were refused -> how many.
    """

    candidates: list[dict[str, Any]]
    attempts: int
    settings: PlanSettings
    rejected: dict[str, int] = field(default_factory=dict)

    @property
    def complete(self) -> bool:
        """Return whether every candidate asked for was found."""
        return len(self.candidates) == self.settings.count

    def summary(self) -> str:
        """Return one line: how many were found, in how many IKs, why others were not."""
        why = ', '.join(f'{n} {k}' for k, n in sorted(self.rejected.items())) or 'none'
        return (f'planned {len(self.candidates)} of {self.settings.count} candidates in '
                f'{self.attempts} IKs (seed {self.settings.seed}; rejected: {why})')

    def lines(self) -> list[str]:
        """Return the candidates as JSON Lines (without line breaks)."""
        return [json.dumps(c, separators=(', ', ': ')) for c in self.candidates]


def _object_shape(scenario: Scenario, shape: ObjectShape | None) -> ObjectShape:
    if shape is not None:
        return shape
    if scenario.object is None:
        raise InputError('object', 'the planner needs an object: give one (shape, size, '
                         'mass) or a base scenario with one')
    return ObjectShape.from_spec(scenario.object)


def plan_grasps(scenario: Scenario | str | Path, settings: PlanSettings = PlanSettings(),
                shape: ObjectShape | None = None, mass: float | None = None) -> PlanResult:
    """
    Plan candidate grasps of an object by a hand (see the module docstring).

    Args:
        scenario: the base scenario (a file or a validated one): the hand, its torque
            limits, friction, gravity and the grasp the draws start from.
        settings: what to plan.
        shape: the object's shape; None: the base scenario's object.
        mass: the object's mass [kg]; None: the base scenario's object's.

    Returns:
        At most ``settings.count`` candidates, fewer when ``count * attempts`` IKs did
        not find them.

    Raises:
        InputError: a bad setting, object or link (naming it).
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    # Only the hand is used: the candidates replace the base's contacts, whose distance
    # to this object (a box's, not the sphere they were written for) says nothing.
    setup, _ = bind_for_candidates(scenario)
    hand = setup.hand
    shape = _object_shape(scenario, shape)
    if mass is None:
        if scenario.object is None:
            raise InputError('object.mass', 'give the mass of the object')
        mass = scenario.object.mass
    if not (math.isfinite(mass) and mass > 0.0):
        raise InputError('object.mass', f'must be finite and > 0 [kg], got {mass!r}')
    if scenario.gravity is None and settings.extra_load is None:
        raise InputError('load', 'the base scenario has no gravity: give the load')
    links = list(settings.links or [c.link for c in scenario.contacts])
    if not links:
        raise InputError('links', 'no contact links: give them (the base scenario has none)')
    urdf = resolve_urdf(scenario.urdf, scenario.base_dir)
    keep = None if settings.shapes == 'robot' else hand_links(hand) | set(links)
    geom = collision_model(hand, urdf, links=keep)  # read once, for the check and the IK
    _refuse_mesh_on_mesh(hand, geom, shape, links)
    check = GeometryContacts.bind(hand, urdf, shape, settings.tolerance, links=links,
                                  max_penetration=1.0, field='links', geometry=geom)
    ik = SurfaceIK(hand, urdf, shape, links, EDGE, geom)
    model = hand.model
    lower = model.lowerPositionLimit[hand.idx_q] + settings.joint_margin
    upper = model.upperPositionLimit[hand.idx_q] - settings.joint_margin
    lower, upper = np.minimum(lower, upper), np.maximum(lower, upper)
    centre = np.asarray(settings.centre if settings.centre is not None
                        else scenario.object_origin, dtype=float)
    region = (centre - settings.region, centre + settings.region)
    rng = np.random.default_rng(settings.seed)
    theta_base = setup.q[hand.idx_q]
    frame = opposition_frame(setup)
    load = _load(mass, scenario.gravity, settings.extra_load)
    margin = (None if settings.hold_margin is None
              else max(settings.hold_margin, scenario.friction.margin))
    out: list[dict[str, Any]] = []
    rejected: dict[str, int] = {}
    tries = 0
    while len(out) < settings.count and tries < settings.count * settings.attempts:
        tries += 1
        p0 = rng.uniform(region[0], region[1])
        R = _draw_orientation(shape.kind, shape.size, settings, frame, rng)
        theta0 = np.clip(theta_base + rng.normal(0.0, settings.joint_spread, hand.m),
                         lower, upper)
        sol = ik.solve(theta0, p0, R, setup.q, (lower, upper), region, settings.clearance,
                       tolerance=settings.tolerance)
        q = ik.full_q(sol.theta, setup.q)
        pose = pin.SE3(R, sol.position)
        why, found = _reject(check, ik, q, pose, links, settings)
        if why is None and margin is not None:
            why = _not_held(setup, q, found, sol.position, load, margin)
        if why is not None:
            rejected[why] = rejected.get(why, 0) + 1
            continue
        out.append(_candidate(f'plan-{settings.seed}-{len(out)}', hand, sol.theta,
                              sol.position, R, shape, mass, found, settings,
                              scenario.gravity))
    return PlanResult(out, tries, settings, rejected)


def _refuse_mesh_on_mesh(hand, geom: pin.GeometryModel, shape: ObjectShape,
                         links: list[str]) -> None:
    """
    Refuse a mesh object when a contact link's collision shape is a mesh too.

    coal's distance between two triangle meshes gives no normal, so the check could
    place no contact: without this every IK was refused as an overlap (the G1's
    fingers are meshes).
    """
    if shape.kind != 'mesh':
        return
    meshed = [link for link in links if any(
        isinstance(g.geometry, coal.BVHModelBase)
        and hand.model.frames[g.parentFrame].name == link for g in geom.geometryObjects)]
    if meshed:
        raise InputError('mesh', f"contact links {', '.join(meshed)} are meshes: between two "
                         'meshes coal gives no contact normal; plan this hand with an '
                         'object shape (--object sphere|box|cylinder)')


def _load(mass: float, gravity, extra) -> np.ndarray:
    """Return the candidate's own load: the weight at the object's centre plus ``extra``."""
    load = np.asarray(extra if extra is not None else [0.0] * 6, dtype=float).copy()
    if gravity is not None:
        load[:3] += mass * np.asarray(gravity, dtype=float)
    return load


def opposition_frame(setup) -> tuple[np.ndarray, float] | None:
    """
    Return the base grasp's opposition frame, columns (d, e, d x e), and its row's span.

    d is the axis the contact normals share most (the principal axis of sum n n^T: the
    fingers' against the thumb's), e the direction the contact points spread most
    across d (the fingers' row); the span is their extent along e [m]. None with fewer
    than two contacts.
    """
    if len(setup.contacts) < 2:
        return None
    maps = setup.maps()
    normals = maps.rotations[:, :, 2]
    d = np.linalg.eigh(normals.T @ normals)[1][:, -1]
    spread = maps.positions - maps.positions.mean(axis=0)
    spread = spread - np.outer(spread @ d, d)
    e = np.linalg.eigh(spread.T @ spread)[1][:, -1]
    e = e - (e @ d) * d
    e /= np.linalg.norm(e)
    span = float(np.ptp(maps.positions @ e))
    return np.column_stack([d, e, np.cross(d, e)]), span


def _draw_orientation(kind: str, box_size, settings: PlanSettings, frame, rng
                      ) -> np.ndarray:
    """
    Draw the object's orientation in the base frame.

    ``opposed`` (``frame``: :func:`opposition_frame`'s): a box with one of its axes
    along the opposition axis d (its faces across it, the thumb against the fingers)
    and another along the fingers' row e, one whose face is wide enough for the row; a
    cylinder with its axis along e (the fingers and the thumb on its curved side,
    normals towards the axis), turned about it at random; then tilted by a rotation
    vector of standard deviation :data:`TILT` per axis. A sphere's is never drawn.
    """
    if not settings.rotate or kind == 'sphere':
        return np.eye(3)
    if settings.orientation == 'random' or frame is None or kind not in ('box', 'cylinder'):
        # Uniform over rotations: a unit quaternion (x, y, z, w) from four normals, as
        # SciPy's Rotation.random draws it (pinocchio's is taken to keep SciPy's
        # rotations out of the planner's start-up).
        x, y, z, w = rng.normal(size=4)
        return pin.Quaternion(w, x, y, z).normalized().toRotationMatrix()
    frame, span = frame
    d, e = frame[:, 0], frame[:, 1]
    if kind == 'box':
        # Along the fingers' row an axis whose face takes it (off the edges), else the
        # longest; across the grasp one of the other two at random.
        size = np.asarray(box_size, dtype=float)
        fits = [a for a in range(3) if size[a] >= span + 4.0 * EDGE] or [int(np.argmax(size))]
        row = int(rng.choice(fits))
        across = int(rng.choice([a for a in range(3) if a != row]))
        perm = np.array([across, row, 3 - across - row])
        signs = rng.choice([-1.0, 1.0], 3)
        P = np.zeros((3, 3))
        P[perm, np.arange(3)] = signs
        R = frame @ P.T  # object axis perm[i] (signed) along frame column i
        if np.linalg.det(R) < 0.0:
            R[:, perm[2]] *= -1.0
    else:
        turn = pin.exp3(e * rng.uniform(0.0, 2.0 * math.pi))
        R = turn @ np.column_stack([d, np.cross(e, d), e])
    tilt = pin.exp3(rng.normal(0.0, TILT, 3))
    return tilt @ R


def _not_held(setup, q: np.ndarray, found, position: np.ndarray, load: np.ndarray,
              margin: float) -> str | None:
    """
    Return why a touching candidate is not kept for its load, or None (it is held).

    Held: its load capacity (the certified LP of :mod:`.capacity`, every load from zero
    up to it held with friction margin ``margin``) is at least 1 (:func:`.capacity.load_capacity`'s
    verdict; what binds is not named).
    """
    candidate = dataclasses.replace(
        setup, q=q, contacts=found.specs(), object_origin=np.asarray(position, float),
        external_wrench=load, friction=dataclasses.replace(setup.friction, margin=margin))
    try:
        # What binds is not written, and a zero load DAQP does not hold is not confirmed
        # by HiGHS (SciPy's import was 0.3 s of a plan): either way it is dropped.
        cap = load_capacity(candidate, explain=False, confirm=False)
    except (InputError, GeometryError):
        return 'no grasp maps'
    if cap.status == 'unbounded' or (cap.status == 'optimal' and cap.value >= 1.0):
        return None
    if cap.status == 'failed':
        return 'capacity failed'
    return 'infeasible for its load'


def _reject(check: GeometryContacts, ik: SurfaceIK, q: np.ndarray, pose: pin.SE3,
            links: list[str], settings: PlanSettings) -> tuple[str | None, Any]:
    """
    Return why a solution is not a candidate, or None (the independent check).

    And the contacts found (None before they are looked for).
    """
    model = check.hand.model
    if np.any(q < model.lowerPositionLimit - 1e-12) or np.any(
            q > model.upperPositionLimit + 1e-12):
        return 'joint limits', None
    try:
        found = check.contacts(q, pose)
    except GeometryError:
        return 'overlap', None
    if found.links != tuple(links) or np.any(np.abs(found.distances) > settings.tolerance):
        return 'contact off the surface', found
    if any(on_edge(check.object, pose.actInv(p), EDGE) for p in found.object_points):
        return 'contact at an edge', found
    # Every shape measured (no bound), as before issue 36: not the IK's broad phase.
    others = {k: d for k, d in ik.distances(q, pose).items() if k not in links}
    if others and min(others.values()) < settings.clearance:
        return 'another link too close', found
    return None, found


def on_edge(shape: ObjectShape, x: np.ndarray, margin: float) -> bool:
    """
    Tell whether a surface point (object frame) is within ``margin`` of an edge.

    A box's edges and a cylinder's rims: a contact there has no one normal (a finger
    on an edge is not the grasp the statics planned). A sphere and a mesh have none.
    """
    size = shape.size
    if shape.kind == 'box':
        return int(np.sum(np.abs(x) > 0.5 * size - margin)) > 1
    if shape.kind == 'cylinder':
        return bool(np.hypot(x[0], x[1]) > size[0] - margin
                    and abs(x[2]) > 0.5 * size[1] - margin)
    return False


def _floats(values, digits: int = 9) -> list[float]:
    return [round(float(v), digits) for v in values]


def _candidate(cid: str, hand, theta: np.ndarray, position: np.ndarray, R: np.ndarray,
               shape: ObjectShape, mass: float, found, settings: PlanSettings,
               gravity) -> dict[str, Any]:
    """Return one candidate: a partial scenario (docs/planner.md, "Batch scoring")."""
    if settings.contacts == 'points' or shape.kind == 'mesh':
        contacts = [{'link': link, 'position': _floats(pt), 'normal': _floats(n)}
                    for link, pt, n in zip(found.links, found.points_link, found.normals)]
    else:
        contacts = [{'link': link} for link in found.links]
    grasp = {'joint_positions': dict(zip(hand.joints, _floats(theta))),
             'object_origin': _floats(position), 'contacts': contacts,
             'contact_tolerance': 2.0 * settings.tolerance}
    out: dict[str, Any] = {'id': cid, 'grasp': grasp}
    extra = np.asarray(settings.extra_load or [0.0] * 6, dtype=float)
    if shape.kind == 'mesh':
        # A scenario's object is a primitive: a mesh's weight (at its frame's origin,
        # taken as its centre of mass) is written out as the whole load.
        weight = np.zeros(6)
        if gravity is not None:
            weight[:3] = mass * np.asarray(gravity, dtype=float)
        out.update({'object': None, 'gravity': None,
                    'load': {'external_wrench': _floats(weight + extra)}})
        return out
    out['object'] = {'shape': shape.kind, 'size': _floats(shape.size), 'mass': float(mass),
                     'position': _floats(position),
                     'rpy': _floats(pin.rpy.matrixToRpy(R))}
    out['load'] = {'external_wrench': _floats(extra)}
    return out
