# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Scoring one candidate grasp of a batch: the job, the candidate lines, the single path.

A batch is a base scenario (the hand, and every default) and candidates, one
JSON object per line (JSON Lines, docs/planner.md). Each line is a partial
scenario, merged into the base one: a mapping merges key by key (so
``{"grasp": {"joint_positions": {"joint_0.0": 0.1}}}`` moves one joint), anything
else replaces (a ``contacts`` list replaces the base's list), and ``null``
removes the key from the base (``"gravity": null`` with a
``load.external_wrench`` makes that wrench the whole load). ``id`` (any JSON
value) names the candidate; the line number is always kept. ``hand`` cannot be
given (one hand per batch). The merged document is validated as a scenario
file, so a bad line fails with the scenario's own message, prefixed
``line N:``, e.g. ``line 7: grasp.contacts[0].link: frame 'tip' not found ...``,
and the batch goes on.

Each candidate is solved (tau-QP, the batch's backend and objective) and, with
``metrics="full"``, gets its load capacity and the 12 axis capacities
(:mod:`.capacity`). A record (plain data) per candidate: ``line``, ``id``,
``status`` (``optimal``, ``infeasible``, ``failed``, or ``error`` for a bad
line), ``error``, ``torque_norm`` [N m], ``max_torque_ratio`` [-],
``friction_usage_max`` [-], ``friction_usage`` (per contact), ``capacity``
[-] (every load from zero to it held), ``capacity_status``, ``capacity_reason``,
``capacities`` (direction -> N or N m, null where not certified), ``holdable_fraction``
(infeasible candidates: their capacity), ``time_s`` [s] and ``rank``; with ``solutions=True``
also ``tau`` (joint torques [N m], the base hand's joint order) and ``wrenches``
(per contact [f_x, f_y, f_z, m_z] in its contact frame [N, N m]), null unless
optimal, so the winner need not be solved again.

Candidates may also be given in memory (:func:`score_batch`): a mapping (the
same partial scenario as a line's JSON object) or a :class:`GraspSetup` of the
base hand (pickled to the workers: about 1 MB each for the Allegro), numbered
1, 2, ... in the order given.

The batch runs over processes or a Dask cluster in :mod:`.engines`
(:func:`~grasp_torque_opt.methods.engines.score_batch`).
"""

from __future__ import annotations

from collections.abc import Iterable
import copy
import dataclasses
from dataclasses import dataclass
import hashlib
import json
from pathlib import Path
import time
from typing import Any

from grasp_torque_opt.backends import make_solver
from grasp_torque_opt.core.exceptions import GraspTorqueError, InputError
from grasp_torque_opt.core.grasp_setup import bind_for_candidates, GraspSetup, issue_once
from grasp_torque_opt.core.scenario import OBJECTIVES, parse_scenario
from grasp_torque_opt.core.scenario_contacts import resolve_contacts
from grasp_torque_opt.methods.capacity import CapacityLP, direction_capacities
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.methods.explain import holdable
import numpy as np
import yaml

#: Metrics: ``basic`` (solve: status, norms, ratio, usage) or ``full`` (plus capacities).
METRICS = ('basic', 'full')
#: Keys a candidate line may hold: ``id`` and the scenario's sections except ``hand``.
CANDIDATE_KEYS = ('id', 'grasp', 'friction', 'load', 'gravity', 'object', 'objective')
#: A longer line is refused unread (bounded memory per candidate) [characters].
MAX_LINE = 1_000_000


@dataclass(frozen=True)
class ScoreJob:
    """
    What every worker needs: the base scenario's text and the batch's options.

    Attributes:
        scenario_text: the base scenario file's contents (YAML).
        base_dir: the folder its relative paths are relative to (must exist on workers).
        source: the base scenario's name, for messages.
        metrics: one of :data:`METRICS`.
        backend: the tau-QP backend (default DAQP, the fastest here).
        fallback: the backend asked when the first gives nothing certifiable, or None.
        objective: override of the scenario's ``objective.type``, or None.
        solutions: also record ``tau`` and ``wrenches`` (off by default: records
            stay small).
    """

    scenario_text: str
    base_dir: str
    source: str = '<scenario>'
    metrics: str = 'full'
    backend: str = 'daqp'
    fallback: str | None = 'proxsuite'
    objective: str | None = None
    solutions: bool = False

    @classmethod
    def from_file(cls, path: str | Path, **options: Any) -> ScoreJob:
        """
        Make the job of a base scenario file.

        Raises:
            InputError: the file cannot be read (field ``scenario``).
        """
        path = Path(path)
        try:
            text = path.read_text()
        except OSError as e:
            raise InputError('scenario', f'cannot read {path}: {e.strerror}') from e
        return cls(scenario_text=text, base_dir=str(path.resolve().parent), source=str(path),
                   **options)

    @property
    def key(self) -> str:
        """Return a digest that identifies the job (a worker's cache key)."""
        return hashlib.sha256(repr(self).encode()).hexdigest()


def merge(base: Any, override: Any) -> Any:
    """
    Merge a candidate into the base document: mappings key by key, ``None`` removes.

    Copies only what changes; the base is never modified.
    """
    if not (isinstance(base, dict) and isinstance(override, dict)):
        return override
    out = dict(base)
    for key, value in override.items():
        if value is None:
            out.pop(key, None)
        else:
            out[key] = merge(base.get(key), value)
    return out


class Scorer:
    """Scores candidates of one job in this process (one bound hand, one solver)."""

    def __init__(self, job: ScoreJob) -> None:
        if job.metrics not in METRICS:
            raise ValueError(f"metrics must be one of {', '.join(METRICS)}, got {job.metrics!r}")
        if job.objective is not None and job.objective not in OBJECTIVES:
            raise InputError('objective', f"must be one of {', '.join(OBJECTIVES)}, "
                             f'got {job.objective!r}')
        self.job = job
        try:
            doc = yaml.safe_load(job.scenario_text)
        except yaml.YAMLError as e:
            raise InputError('scenario', f'{job.source} is not valid YAML: {e}'
                             .splitlines()[0]) from e
        self.base_dir = Path(job.base_dir)
        self.doc = doc
        self.base, self.base_warnings = bind_for_candidates(  # warned when a line keeps
            parse_scenario(doc, self.base_dir, job.source))     # the contacts (_bind)
        self.solver = make_solver(job.backend)
        self.fallback = (make_solver(job.fallback) if job.fallback not in (None, job.backend)
                         else None)

    def candidate(self, lineno: int, text: str | dict | GraspSetup) -> tuple[Any, GraspSetup]:
        """
        Return the candidate of one line (or in-memory candidate), bound to the base hand.

        Args:
            lineno: its line number (in-memory: its position, from 1).
            text: a JSON object's text, the same as a mapping, or a bound setup.

        Raises:
            InputError: naming the line and the field.
        """
        if isinstance(text, GraspSetup):
            if text.hand.joints != self.base.hand.joints:
                raise InputError(f'line {lineno}', 'a GraspSetup of another hand (joints '
                                 f'{text.hand.joints[:3]}..., the base has '
                                 f'{self.base.hand.joints[:3]}...)')
            setup = text
            if self.job.objective:
                setup = dataclasses.replace(setup, objective=self.job.objective)
            return lineno, setup
        if isinstance(text, dict):
            return self._bind(lineno, copy.deepcopy(text))
        if not isinstance(text, str):
            raise InputError(f'line {lineno}', 'a candidate is a JSON text, a mapping or a '
                             f'GraspSetup, got {type(text).__name__}')
        if len(text) > MAX_LINE:
            raise InputError(f'line {lineno}', f'longer than {MAX_LINE} characters')
        try:
            data = json.loads(text)
        except json.JSONDecodeError as e:
            raise InputError(f'line {lineno}', f'not valid JSON: {e}') from e
        except RecursionError as e:  # '[[[[...' nested beyond Python's stack
            raise InputError(f'line {lineno}', 'nested too deeply') from e
        if not isinstance(data, dict):
            raise InputError(f'line {lineno}', f'must be a JSON object, got '
                             f'{type(data).__name__}')
        return self._bind(lineno, data)

    def _bind(self, lineno: int, data: dict) -> tuple[Any, GraspSetup]:
        """Merge a candidate's mapping into the base scenario and bind it to the hand."""
        for key in data:
            if key not in CANDIDATE_KEYS:
                raise InputError(f'line {lineno}: {key}', 'unknown or fixed field (allowed: '
                                 f"{', '.join(CANDIDATE_KEYS)}; the hand is the base "
                                 "scenario's)")
        ident = data.pop('id', lineno)
        if 'contacts' not in (data.get('grasp') if isinstance(data.get('grasp'), dict) else {}):
            issue_once(self.base_warnings)  # the line keeps the base's contacts
        try:
            scenario = parse_scenario(merge(self.doc, data), self.base_dir, f'line {lineno}')
            base = self.base
            hand = base.hand
            weights = (np.ones(hand.m) if scenario.weights is None
                       else np.asarray(scenario.weights, dtype=float))
            if weights.shape != (hand.m,):
                raise InputError('objective.weights', f'must have {hand.m} entries (one per '
                                 f'joint), got {weights.size}')
            q = hand.configuration(scenario.joint_positions)
            setup = GraspSetup(
                hand=hand, q=q, contacts=resolve_contacts(scenario, hand, q),
                object_origin=scenario.object_origin,
                friction=scenario.friction, external_wrench=scenario.external_wrench,
                weights=weights, objective=self.job.objective or scenario.objective)
        except InputError as e:
            raise InputError(f'line {lineno}: {e.field}', e.problem) from e
        return ident, setup

    def score_line(self, lineno: int, text: str | dict | GraspSetup) -> dict[str, Any]:
        """Return the record of one line (a bad line gives status ``error``; never raises)."""
        t0 = time.perf_counter()
        record: dict[str, Any] = {'line': lineno, 'id': None}
        try:
            record['id'], setup = self.candidate(lineno, text)
            maps = setup.maps()
        except InputError as e:
            msg = str(e)
            if not msg.startswith(f'line {lineno}'):
                msg = f'line {lineno}: {msg}'
            return {**record, 'status': 'error', 'error': msg,
                    'time_s': time.perf_counter() - t0}
        except GraspTorqueError as e:
            return {**record, 'status': 'error', 'error': f'line {lineno}: {e}',
                    'time_s': time.perf_counter() - t0}
        try:
            record.update(self.score(setup, maps))
        except GraspTorqueError as e:
            record.update(status='failed', error=f'line {lineno}: {e}')
        except Exception as e:  # noqa: BLE001 -- one candidate never stops the batch
            record.update(status='failed', error=f'line {lineno}: {type(e).__name__}: {e}')
        record['time_s'] = time.perf_counter() - t0
        return record

    def score(self, setup: GraspSetup, maps) -> dict[str, Any]:
        """Return the metrics of one bound candidate (plain data)."""
        sol = solve(setup, maps=maps, solver=self.solver, fallback=self.fallback)
        usage = sol.friction_usage
        out: dict[str, Any] = {
            'status': sol.status, 'error': None, 'torque_norm': sol.torque_norm,
            'max_torque_ratio': sol.max_torque_ratio,
            'friction_usage_max': None if usage is None else float(usage.max()),
            'friction_usage': None if usage is None else [float(u) for u in usage],
            'backend': sol.backend, 'solve_time_s': sol.solve_time_s,
        }
        if self.job.solutions:
            out['tau'] = None if sol.tau is None else [float(t) for t in sol.tau]
            out['wrenches'] = (None if sol.wrenches is None
                               else [[float(v) for v in w] for w in sol.wrenches])
        if self.job.metrics == 'full':
            out.update(self.capacities(setup, maps, sol.status))
        return out

    def capacities(self, setup: GraspSetup, maps, status: str) -> dict[str, Any]:
        """Return the full metrics of a bound candidate solved with ``status`` (plain data)."""
        lp = CapacityLP(setup, maps)
        cap = lp.solve(setup.external_wrench, binding=False)
        fraction, reason = holdable(cap, status)
        return {'capacity': cap.value, 'capacity_status': cap.status,
                'capacity_reason': reason, 'holdable_fraction': fraction,
                'capacities': {k: c.value for k, c in
                               direction_capacities(setup, maps, lp, binding=False).items()}}

    def score_lines(self, lines: Iterable[tuple[int, Any]]) -> list[dict[str, Any]]:
        """Score (line number, candidate) pairs into records, in order."""
        return [self.score_line(n, t) for n, t in lines]
