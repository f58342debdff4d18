# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Batch scoring at the solver's speed: many candidates of one hand, bound once.

:class:`BatchScorer` scores a chunk of candidate lines (:mod:`.score`'s) in stages,
each over the whole chunk: a cheap parse of the fields that vary (joint positions,
contacts, load); the kinematics of every configuration in one compiled call
(:mod:`grasp_torque_opt.core.tree_kinematics`); the maps and the tau-QP of every
candidate in one compiled call (``build_batch``: the compiled cycle's maps stage and
its QR build written for the batch); one DAQP solve per candidate, each warm-started
from its neighbour's active set (a warm answer off the KKT check or the certificate is
solved again cold); then the KKT check, the certificate against the exact cone and
the planner's numbers of every answer in one compiled call (``finish_batch``). Full metrics then
solve :mod:`.capacity`'s LPs as the single path does, their checks in one compiled
call (:mod:`.batch_capacity`).

Everything else goes to the single path (:meth:`Scorer.score_line`), whose answer is
then the record, so a record never depends on the path: a line with another field
(``friction``, ``object``, ``objective``, ``grasp.object_origin``, a ``gravity``
other than null) or anything the cheap parse does not accept (bad JSON, an unknown
joint or link, a value that is not a finite number, ...: the single path then names
the error), a candidate the compiled stages hand back (a contact frame that cannot be
made, A = [G; J^T] not of full column rank), and every answer that is not certified
optimal here (infeasible, failed: the single path confirms an infeasible load with
its LP). The whole batch takes the single path when the job or the base scenario is
outside what the stages do (:attr:`BatchScorer.why_not` says why): a backend other
than DAQP, the min-max objective, coupled joints, ``hand.base_link``, a name map, a
joint other than 1-DoF revolute or prismatic, or no compiled cycle.
"""

from __future__ import annotations

from collections.abc import Iterable
import json
import math
import time
from typing import Any

from grasp_torque_opt.backends.daqp import KKT_TOLERANCE
from grasp_torque_opt.core.certificate import DEFAULT_TOLERANCE
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.friction import contact_block
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup, issue_once
from grasp_torque_opt.core.margin import planned_friction
from grasp_torque_opt.core.scenario import MAX_CONTACTS, parse_scenario, SHAPES
from grasp_torque_opt.core.scenario_contacts import from_geometry
from grasp_torque_opt.core.tau_qp import BOX_MARGIN, QR_RTOL
from grasp_torque_opt.core.tree_kinematics import supported, TreeKinematics
from grasp_torque_opt.methods.batch_capacity import CapacityBatch
from grasp_torque_opt.methods.score import MAX_LINE, merge, Scorer
from grasp_torque_opt.native import loader
import numpy as np

#: Keys a line may hold for the batch stages (anything else: the single path).
FAST_KEYS = frozenset(('id', 'grasp', 'load', 'gravity', 'object'))
#: Keys of a line's ``grasp`` the batch stages take.
GRASP_KEYS = frozenset(('joint_positions', 'contacts', 'object_origin', 'contact_tolerance'))
_CONTACT_KEYS = frozenset(('link', 'position', 'normal', 'tangent'))
_OBJECT_KEYS = frozenset(('shape', 'size', 'mass', 'position', 'rpy'))
_ORIGIN = [0.0, 0.0, 0.0]


class _Skip(Exception):
    """The cheap parse does not take this line: the single path scores it."""


try:  # a line read in 5 us instead of the standard library's 20 (a planned Allegro line)
    from orjson import loads as _orjson_loads
except ImportError:  # optional: the standard library's then
    _orjson_loads = None


def loads(text: str) -> Any:
    """
    Return the JSON value of ``text`` as the standard library reads it, by orjson if installed.

    A line orjson refuses (NaN or Infinity, a number beyond a double, nesting deeper than
    1,024) raises ValueError: the batch stages skip it and the single path reads it with
    the standard library, as every line was read before. orjson reads an integer beyond
    64 bits as a float: a line whose ``id`` came out a float is read again by the
    standard library, so that its id is written back as given.
    """
    if _orjson_loads is None:
        return json.loads(text)
    data = _orjson_loads(text)
    if isinstance(data, dict) and type(data.get('id')) is float:
        return json.loads(text)
    return data


#: Markers of :meth:`BatchScorer.parse`: the base has no load section, and a zero one.
_NO_LOAD = object()
_ZERO_LOAD = [0.0] * 6
#: The JSON number types (a bool is not one: ``type(True)`` is ``bool``).
_NUMBER_TYPES = frozenset((int, float))


def _numbers(values: list) -> list:
    """
    Return ``values`` if every one is a finite JSON number (int or float, not bool).

    Raises:
        _Skip: any other (a sum that overflows is skipped as well: the single path
            then decides).
    """
    if not _NUMBER_TYPES.issuperset(map(type, values)):
        raise _Skip
    try:
        total = sum(values, 0.0)  # NaN or inf anywhere makes it non-finite
    except OverflowError as e:  # an int of more than 308 digits
        raise _Skip from e
    if not math.isfinite(total):
        raise _Skip
    return values


def _vec3(v: Any) -> list[float]:
    """Return ``v`` if it is a list of 3 finite JSON numbers (:func:`_numbers`, unrolled)."""
    if not isinstance(v, list) or len(v) != 3:
        raise _Skip
    x, y, z = v
    types = _NUMBER_TYPES
    # A sum that overflows raises OverflowError (an int of more than 308 digits): the
    # caller skips the line then too.
    if (type(x) not in types or type(y) not in types or type(z) not in types
            or not math.isfinite(x + y + z)):
        raise _Skip
    return v


def parse_contacts(raw: Any, hand) -> tuple:
    """
    Return the contact arrays of a line's ``grasp.contacts``, read as parse_scenario does.

    Plain lists (points, normals, has_normal, tangents, has_tangent: one entry per
    contact), made arrays once per group (:meth:`BatchScorer._group`).

    Raises:
        _Skip: anything it does not take, and a contact without a ``position`` (found
            from geometry by the single path).
    """
    if not isinstance(raw, list) or not 0 < len(raw) <= MAX_CONTACTS:
        raise _Skip
    points, normals, tangents, has_n, has_t, links, fids = [], [], [], [], [], [], []
    for c in raw:
        if not isinstance(c, dict) or not _CONTACT_KEYS.issuperset(c):
            raise _Skip
        link = c.get('link')
        if not isinstance(link, str) or not link:
            raise _Skip
        try:
            fids.append(hand.frame_index(link, 'link'))
        except InputError as e:
            raise _Skip from e
        links.append(link)
        if c.get('position') is None:  # found from geometry (or an error): the single path
            raise _Skip
        points.append(_vec3(c['position']))
        normal = _unit(c.get('normal'))
        normals.append(normal or _ORIGIN)
        has_n.append(normal is not None)
        tangents.append(_tangent(c.get('tangent'), normal))
        has_t.append(c.get('tangent') is not None)
    return tuple(fids), tuple(links), points, normals, has_n, tangents, has_t


def _unit(v: Any) -> list[float] | None:
    """Return a contact's normal divided by its norm, or None if not given (else _Skip)."""
    if v is None:
        return None
    x, y, z = _vec3(v)
    norm = math.hypot(x, y, z)
    if not (1e-9 <= norm < math.inf):
        raise _Skip
    return [x / norm, y / norm, z / norm]


def _tangent(v: Any, normal: list[float] | None) -> list[float]:
    """Return a contact's tangent as given (zeros if not), checked as parse_scenario does."""
    if v is None:
        return _ORIGIN
    t = _vec3(v)
    u = _unit(t)
    if normal is not None:
        along = sum(a * b for a, b in zip(u, normal))
        if math.hypot(*(a - along * b for a, b in zip(u, normal))) < 1e-6:
            raise _Skip
    return t


def object_weight(value: Any) -> tuple[float, list | None]:
    """
    Return (mass, position or None) of an ``object`` section, checked as parse_scenario does.

    Raises:
        _Skip: anything it does not take (the single path then decides).
    """
    if not isinstance(value, dict) or not _OBJECT_KEYS.issuperset(value):
        raise _Skip
    shape, size, mass = value.get('shape'), value.get('size'), value.get('mass')
    if not isinstance(shape, str) or shape not in SHAPES:
        raise _Skip
    if not isinstance(size, list) or len(size) != len(SHAPES[shape]):
        raise _Skip
    if min(_numbers(size)) <= 0 or _numbers([mass])[0] <= 0:
        raise _Skip
    for key in ('position', 'rpy'):
        if value.get(key) is not None:
            _vec3(value[key])
    return float(mass), value.get('position')


def _tolerance(value: Any) -> None:
    """Check a line's ``grasp.contact_tolerance`` as parse_scenario does (else _Skip)."""
    if _numbers([value])[0] <= 0:
        raise _Skip


def why_not(scorer: Scorer) -> str:
    """Say why a job takes the single path for every line ('' if it does not)."""
    job, setup, hand = scorer.job, scorer.base, scorer.base.hand
    module = loader.fast_cycle
    if module is None or not hasattr(module, 'kinematics_batch'):
        return loader.IMPORT_ERROR or 'the compiled cycle has no batch stages'
    if job.backend != 'daqp':
        return f'backend {job.backend} (the batch stages solve with DAQP)'
    if (job.objective or setup.objective) != 'sum-of-squares':
        return 'objective min-max (the batch stages solve the sum of squares)'
    if hand.velocity_map is not None or hand.coupling.mimics:
        return 'coupled joints'
    if hand.base_link is not None:
        return 'hand.base_link'
    if isinstance(scorer.doc.get('hand'), dict) and scorer.doc['hand'].get('name_map'):
        return 'hand.name_map'
    return supported(hand.model)


def contact_arrays(hand, specs) -> tuple:
    """(frame ids, links, points, normals, has_normal, tangents, has_tangent) of specs."""
    p = len(specs)
    normals, tangents = np.zeros((p, 3)), np.zeros((p, 3))
    has_n, has_t = np.zeros(p, dtype=bool), np.zeros(p, dtype=bool)
    for i, spec in enumerate(specs):
        if spec.normal is not None:
            normals[i], has_n[i] = spec.normal, True
        if spec.tangent is not None:
            tangents[i], has_t[i] = spec.tangent, True
    links = tuple(spec.link for spec in specs)
    fids = tuple(hand.frame_index(link, f'grasp.contacts[{i}].link')
                 for i, link in enumerate(links))
    points = np.array([spec.position for spec in specs], dtype=float).reshape(p, 3)
    return fids, links, points, normals, has_n, tangents, has_t


class BatchScorer:
    """
    Scores chunks of candidates of one job: the batch stages, the single path for the rest.

    Args:
        scorer: the job's single-path scorer (its bound hand, solver and options).
    """

    def __init__(self, scorer: Scorer) -> None:
        self.scorer = scorer
        #: Candidates answered by the batch stages, and by the single path.
        self.staged = 0
        self.single = 0
        self.why_not = why_not(scorer)
        if self.why_not:
            return
        job, setup = scorer.job, scorer.base
        hand = setup.hand
        self.scenario = sc = parse_scenario(scorer.doc, scorer.base_dir, job.source)
        model = hand.model
        self.joint_q = {name: model.joints[model.getJointId(name)].idx_q
                        for name in hand.one_dof_joints(model)}
        self.q0 = setup.q
        self.contacts = contact_arrays(hand, setup.contacts)
        self.origin = np.asarray(setup.object_origin, dtype=float)
        self.base_extra = np.asarray(sc.extra_wrench, dtype=float)
        self.base_has_extra = (isinstance(scorer.doc.get('load'), dict)
                               and scorer.doc['load'].get('external_wrench') is not None)
        self.gravity = None if sc.gravity is None else np.asarray(sc.gravity, dtype=float)
        raw = scorer.doc.get('object')  # the base's object: (mass, its own position or None)
        self.base_object = None if sc.object is None else (
            sc.object.mass, None if raw.get('position') is None else list(sc.object.position))
        # The base's contacts found from geometry: a line that keeps them has them found
        # again at its own configuration (the single path).
        self.base_geometry = from_geometry(sc)
        self.module = loader.fast_cycle
        self.kinematics = TreeKinematics(model, self.module)
        self.kinematics.check(np.array([self.q0]), self.contacts[0])
        friction = planned_friction(setup.friction)
        S_i, b_i = contact_block(friction.mu1, friction.mu2, friction.sides,
                                 friction.min_normal_force)
        s = self.module.Settings()
        s.certificate_tolerance, s.qr_rtol, s.box_margin = DEFAULT_TOLERANCE, QR_RTOL, BOX_MARGIN
        s.eps_abs, s.eps_rel, s.eps_primal_inf = 1e-9, 0.0, 1e-12  # ProxSuite's: unused here
        s.max_iter, s.max_iter_in, s.kkt_tolerance = 1, 1, KKT_TOLERANCE
        s.inner_iteration_s, s.estimate_decay, s.primary_share = 1e-6, 0.5, 1.0
        self.cycle = self.module.FastCycle(
            np.asarray(hand.idx_v, dtype=np.int64), S_i, b_i,
            np.asarray(setup.weights, dtype=float), np.asarray(hand.torque_limits, dtype=float),
            friction.mu1, friction.mu2, setup.friction.mu1, setup.friction.mu2,
            friction.min_normal_force, False, s)
        self.H = np.diag(2.0 * np.asarray(setup.weights, dtype=float))
        self.capacity = CapacityBatch(self.cycle)
        self.daqp = scorer.solver.settings
        import daqp

        self._daqp = daqp

    # -- the cheap parse ---------------------------------------------------------------
    def parse(self, lineno: int, text: Any) -> tuple:
        """
        Return (id, joints, contacts, extra, gravity, origin, object) of a line the stages take.

        ``joints``: (indices in q, positions) or None for the base's; ``contacts``: the
        contact arrays (the base's when not given); ``extra``: the load besides the
        weight (6 numbers, None: the base's); ``gravity``: whether the object's weight is
        added; ``origin``: the line's ``grasp.object_origin`` (None: the base's);
        ``object``: (mass, position or None: at the origin) or None (no object).
        :meth:`inputs` makes the configurations, loads and origins of many.

        Raises:
            _Skip: the single path scores this line.
        """
        data = self._data(text)
        gravity = self.gravity is not None
        if 'gravity' in data:
            if data['gravity'] is not None:
                raise _Skip
            gravity = False
        obj = self.base_object
        if 'object' in data:
            obj = (None if data['object'] is None
                   else object_weight(merge(self.scorer.doc.get('object'), data['object'])))
        joints, contacts, origin = self._grasp(data.get('grasp', {}))
        extra = None if self.base_has_extra else _NO_LOAD
        if 'load' in data:
            load = data['load']
            if not isinstance(load, dict) or set(load) != {'external_wrench'}:
                raise _Skip
            w = load['external_wrench']
            if not isinstance(w, list) or len(w) != 6:
                raise _Skip
            extra = _numbers(w)
        if extra is _NO_LOAD:
            if not (gravity and obj is not None):
                raise _Skip  # the single path says the load is missing
            extra = _ZERO_LOAD
        return data.get('id', lineno), joints, contacts, extra, gravity, origin, obj

    @staticmethod
    def _data(text: Any) -> dict:
        """Return a line's JSON object if its keys are all :data:`FAST_KEYS` (else _Skip)."""
        if isinstance(text, str):
            if len(text) > MAX_LINE:
                raise _Skip
            try:
                data = loads(text)
            except (ValueError, RecursionError) as e:
                raise _Skip from e
        elif isinstance(text, dict):
            data = text
        else:
            raise _Skip
        if not isinstance(data, dict) or not FAST_KEYS.issuperset(data):
            raise _Skip
        return data

    def _grasp(self, grasp: Any) -> tuple:
        """Return (joints, contacts, origin) of a line's ``grasp`` (see :meth:`parse`)."""
        if not isinstance(grasp, dict) or not GRASP_KEYS.issuperset(grasp):
            raise _Skip
        joints, contacts, origin = None, self.contacts, None
        if 'joint_positions' in grasp:
            positions = grasp['joint_positions']
            if not isinstance(positions, dict):
                raise _Skip
            try:
                index = tuple(self.joint_q[name] for name in positions)
            except (KeyError, TypeError) as e:
                raise _Skip from e
            joints = (index, _numbers(list(positions.values())))
        if 'object_origin' in grasp:
            origin = _vec3(grasp['object_origin'])
        if 'contact_tolerance' in grasp:  # only used to find contacts from geometry
            _tolerance(grasp['contact_tolerance'])
        if 'contacts' in grasp:
            contacts = parse_contacts(grasp['contacts'], self.scorer.base.hand)
        elif self.base_geometry:
            raise _Skip
        else:
            issue_once(self.scorer.base_warnings)  # the line keeps the base's contacts
        return joints, contacts, origin

    def inputs(self, parsed: list[tuple]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """
        Return the configurations, loads and object origins of parsed lines (:meth:`parse`).

        Returns:
            (Q, shape (N, nq); W, w_ext = extra + the object's weight about its origin
            where gravity, shape (N, 6); C, the object origins, shape (N, 3)).
        """
        n = len(parsed)
        Q = np.repeat(self.q0[None], n, axis=0)
        rows: dict[tuple, list[int]] = {}
        for r, item in enumerate(parsed):
            if item[1] is not None:
                rows.setdefault(item[1][0], []).append(r)
        for index, rs in rows.items():
            values = np.array([parsed[r][1][1] for r in rs], dtype=float)
            if len(rs) == n:
                Q[:, list(index)] = values
            else:
                Q[np.ix_(rs, index)] = values
        W = np.array([self.base_extra if item[3] is None else item[3] for item in parsed],
                     dtype=float)
        C = np.array([self.origin if item[5] is None else item[5] for item in parsed],
                     dtype=float)
        weighed = [r for r, item in enumerate(parsed) if item[4] and item[6] is not None]
        if weighed:  # as core.scenario.weight_wrench, row by row
            mass = np.array([parsed[r][6][0] for r in weighed], dtype=float)
            at = np.array([C[r] if parsed[r][6][1] is None else parsed[r][6][1]
                           for r in weighed], dtype=float)
            force = mass[:, None] * self.gravity
            W[weighed] += np.concatenate((force, np.cross(at - C[weighed], force)), axis=1)
        return Q, W, C

    # -- the stages ----------------------------------------------------------------------
    def score_lines(self, lines: Iterable[tuple[int, Any]]) -> list[dict[str, Any]]:
        """Score (line number, candidate) pairs into records, in order (never raises)."""
        lines = list(lines)
        if self.why_not:
            return self.scorer.score_lines(lines)
        records: list[dict | None] = [None] * len(lines)
        groups: dict[tuple, list] = {}
        t0 = time.perf_counter()
        for k, (lineno, text) in enumerate(lines):
            try:
                parsed = self.parse(lineno, text)
            except (_Skip, OverflowError):
                continue
            groups.setdefault(parsed[2][1], []).append((k, lineno, parsed))
        parse_s = (time.perf_counter() - t0) / max(1, len(lines))
        for members in groups.values():
            self._group(members, records, parse_s)
        for k, (lineno, text) in enumerate(lines):
            if records[k] is None:
                self.single += 1
                records[k] = self.scorer.score_line(lineno, text)
        return records

    def _group(self, members: list, records: list, parse_s: float) -> None:
        """Score candidates with the same contact links through the batch stages."""
        t0 = time.perf_counter()
        n = len(members)
        parsed = [m[2] for m in members]
        fids = parsed[0][2][0]
        Q, W, C = self.inputs(parsed)
        if all(item[2] is self.contacts for item in parsed):
            arrays = [np.repeat(a[None], n, axis=0) for a in self.contacts[2:]]
        else:
            arrays = [np.array([item[2][j] for item in parsed]) for j in range(2, 7)]
        oMf, J6 = self.kinematics.frames(Q, fids)
        b = self.cycle.build_batch(oMf, J6, arrays[0], arrays[1], arrays[2], arrays[3],
                                   arrays[4], C, W)
        ok = b['ok']
        m = self.scorer.base.hand.m
        A, bu, bl = b['A'], b['bupper'], b['blower']
        sense = np.zeros(m + A.shape[1], dtype=np.int32)
        sense[m:m + b['n_eq']] = 5  # equality
        stage_s = time.perf_counter() - t0
        model = self._model(A, bu, bl, sense, ok)
        times, X, LAM, solved, t1 = self._warm_solves(model, b, n, m)
        fin = self.cycle.finish_batch(b['G'], b['J'], W, b['M1w'], b['M2'], A, bu, bl, X, LAM,
                                      solved, KKT_TOLERANCE)
        self._cold_redo(model, b, W, sense, fin, times, X, LAM, solved)
        share = parse_s + (stage_s + time.perf_counter() - t1) / n
        self._records(members, records, b, (Q, W, C), X, fin, times, share)

    def _warm_solves(self, model, b: dict, n: int, m: int) -> tuple:
        """Solve the group's built QPs warm, in turn: (times, X, LAM, solved, its end)."""
        ok, A, bu, bl = b['ok'], b['A'], b['bupper'], b['blower']
        update, solve = model.update, model.solve
        clock = time.perf_counter
        times, flags = [0.0] * n, [0] * n
        xs, lams = [np.zeros(m)] * n, [np.zeros(m + A.shape[1])] * n
        A_rows, bu_rows, bl_rows = list(A), list(bu), list(bl)
        for i in np.flatnonzero(ok).tolist():  # the solver's loop: nothing else in it
            ts = clock()
            # Warm: DAQP keeps H, f and the last active set (every answer is KKT-checked).
            update(A=A_rows[i], bupper=bu_rows[i], blower=bl_rows[i])
            x, _, flag, info = solve()
            times[i] = clock() - ts
            if flag == 1:
                xs[i], lams[i], flags[i] = x, info['lam'], 1
        t1 = time.perf_counter()
        return times, np.array(xs), np.array(lams), np.array(flags) == 1, t1

    def _cold_redo(self, model, b, W, sense, fin, times, X, LAM, solved) -> None:
        """Solve cold the warm answers off the KKT check or the certificate; update ``fin``."""
        A, bu, bl = b['A'], b['bupper'], b['blower']
        redo = np.flatnonzero(b['ok'] & ~fin['passes'])
        if redo.size:  # warm answers off the KKT check or the certificate: cold
            for i in redo.tolist():
                ts = time.perf_counter()
                x, lam, flag = self._solve(model, A[i], bu[i], bl[i], sense)
                times[i] += time.perf_counter() - ts
                X[i], LAM[i], solved[i] = x, lam, flag == 1
            again = self.cycle.finish_batch(
                b['G'][redo], b['J'][redo], W[redo], b['M1w'][redo], b['M2'][redo], A[redo],
                bu[redo], bl[redo], X[redo], LAM[redo], solved[redo], KKT_TOLERANCE)
            for key in ('passes', 'f', 'usage', 'ratio'):
                fin[key][redo] = again[key]

    def _records(self, members, records, b, inputs, X, fin, times, share) -> None:
        """Write the certified candidates' records (the capacity metrics too when asked)."""
        clock = time.perf_counter
        Q, W, C = inputs
        job = self.scorer.job
        passes = fin['passes'].tolist()
        usage, ratio = fin['usage'], fin['ratio'].tolist()
        usage_max = usage.max(axis=1).tolist()
        usage = usage.tolist()
        norms = np.sqrt(np.einsum('ij,ij->i', X, X)).tolist()
        full = None
        if job.metrics == 'full':  # the capacity LPs of the certified candidates
            t2 = clock()
            good = [i for i in range(len(members)) if passes[i]]
            full = dict(zip(good, self.capacity.metrics(
                b['G'][good], b['J'][good], W[good],
                lambda j: self._bound(Q[good[j]], members[good[j]][2][2], W[good[j]],
                                      C[good[j]], b, good[j]))))
            share += (clock() - t2) / max(1, len(good))
        for i, (k, lineno, (ident, *_)) in enumerate(members):
            if not passes[i]:
                continue  # the single path answers (and confirms an infeasible load)
            ts = clock()
            rec = {'line': lineno, 'id': ident, 'status': 'optimal', 'error': None,
                   'torque_norm': norms[i], 'max_torque_ratio': ratio[i],
                   'friction_usage_max': usage_max[i], 'friction_usage': usage[i],
                   'backend': 'daqp', 'solve_time_s': times[i]}
            if job.solutions:
                rec['tau'] = X[i].tolist()
                rec['wrenches'] = fin['f'][i].reshape(-1, 4).tolist()
            if full is not None:
                rec.update(full[i])
            rec['time_s'] = share + times[i] + clock() - ts
            records[k] = rec
            self.staged += 1

    def _model(self, A, bu, bl, sense, ok):
        """Return a DAQP workspace of the group's size, set up on its first candidate."""
        i = int(np.flatnonzero(ok)[0]) if ok.any() else 0
        model = self._daqp.Model()
        model.setup(self.H.copy(), np.zeros(self.H.shape[0]), A[i].copy(), bu[i].copy(),
                    bl[i].copy(), sense)
        s = model.settings
        s.update(primal_tol=self.daqp.primal_tol, iter_limit=self.daqp.iter_limit, eps_prox=0.0)
        model.settings = s
        self._f = np.zeros(self.H.shape[0])
        self._keep = ()
        return model

    def _solve(self, model, A, bu, bl, sense):
        """One DAQP solve: warm from the last active set (``sense`` None), else cold."""
        model.update(H=self.H, f=self._f, A=A, bupper=bu, blower=bl, sense=sense)
        self._keep = (A, bu, bl)  # buffers DAQP may point to
        x, _, flag, info = model.solve()
        return x, info['lam'], int(flag)

    def _bound(self, q, contacts, wrench, origin, b, i) -> tuple[GraspSetup, GraspMaps]:
        """Return the candidate as the single path binds it, with the batch stages' maps."""
        base = self.scorer.base
        fids, links, points, normals, has_n, tangents, has_t = contacts
        specs = base.contacts if contacts is self.contacts else [
            type(base.contacts[0])(link=link, position=np.array(points[j], dtype=float),
                                   normal=np.array(normals[j], dtype=float) if has_n[j]
                                   else None,
                                   tangent=np.array(tangents[j], dtype=float) if has_t[j]
                                   else None)
            for j, link in enumerate(links)]
        setup = GraspSetup(hand=base.hand, q=q, contacts=specs, object_origin=origin,
                           friction=base.friction, external_wrench=wrench,
                           weights=base.weights, objective='sum-of-squares')
        maps = GraspMaps(G=b['G'][i], J=b['J'][i], links=links, frame_ids=fids,
                         positions=b['positions'][i], rotations=b['rotations'][i],
                         object_origin=origin)
        return setup, maps
