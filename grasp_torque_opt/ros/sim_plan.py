# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The planner's loop's last step: the best-ranked candidate simulated with the node's cycle.

``grasp-torque-sim --plan PLAN --scores SCORES`` reads the lines ``grasp-torque-opt
plan`` wrote and the records ``score --out`` wrote of them, takes the feasible
(``optimal``) record of the best rank, merges its plan line into the base scenario
(the ``--params`` file's, which ``score --scenario`` was given) by score's merge
rule, and simulates it: the node's own cycle (:func:`~grasp_torque_opt.ros.sim_compare.
node_controller`, the friction margin of the scenario) on the rig in simulated time,
without ROS, settle, release and hold for ``--duration`` under the scenario's own
load (its weight, gravity on) and the disturbances asked. Then the picture, with the
node's last certified contact forces beside the simulated ones. bench/plan_physics.py
simulates its candidates with :func:`simulate_candidate` too.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.scenario import parse_scenario, Scenario
from grasp_torque_opt.methods.engines import read_candidates
from grasp_torque_opt.methods.score import merge
from grasp_torque_opt.ros.sim_compare import node_controller
from grasp_torque_opt.sim.episode import EpisodeReport, EpisodeSettings, run_episode, simulated
from grasp_torque_opt.sim.model import SimSettings
import numpy as np
import yaml

#: The status of a record that can be simulated: a certified answer.
FEASIBLE = 'optimal'


def _json_lines(path: Path, field: str) -> dict[int, dict[str, Any]]:
    """Return line number -> JSON object of a JSON Lines file; a bad line names itself."""
    out = {}
    for lineno, text in read_candidates(path):
        try:
            doc = json.loads(text)
        except (json.JSONDecodeError, RecursionError) as e:
            raise InputError(field, f'{path} line {lineno} is not valid JSON') from e
        if not isinstance(doc, dict):
            raise InputError(field, f'{path} line {lineno} is not a JSON object')
        out[lineno] = doc
    if not out:
        raise InputError(field, f'{path} has no lines')
    return out


def best_candidate(plan: str | Path, scores: str | Path) -> tuple[dict, dict]:
    """
    Return the best-ranked feasible record of ``scores`` and its line of ``plan``.

    The record's ``line`` is its line number in the plan file (score's numbering),
    and its ``id`` must be that line's.

    Raises:
        InputError: a file cannot be read or is not score's and plan's output, or no
            record is feasible (field ``--plan`` or ``--scores``).
    """
    lines = _json_lines(Path(plan), '--plan')
    records = list(_json_lines(Path(scores), '--scores').values())
    ranked = [r for r in records if isinstance(r.get('rank'), int)]
    if len(ranked) != len(records):
        raise InputError('--scores', f'{scores}: records without a rank (not the output of '
                         'grasp-torque-opt score --out)')
    best = min((r for r in ranked if r.get('status') == FEASIBLE), key=lambda r: r['rank'],
               default=None)
    if best is None:
        raise InputError('--scores', f'{scores}: no {FEASIBLE} candidate to simulate (of '
                         f'{len(records)})')
    line = lines.get(best.get('line'))
    if line is None or line.get('id', best['line']) != best.get('id', best['line']):
        raise InputError('--plan', f"{plan} line {best.get('line')} is not the candidate "
                         f"{best.get('id')!r} of {scores} (scored from another plan?)")
    return best, line


def candidate_scenario(base: Path, line: dict, **over: Any) -> Scenario:
    """
    Return the base scenario file with a plan line merged in (score's rule), validated.

    ``over``: top-level fields set after the merge (e.g. ``gravity``, ``load``).

    Raises:
        InputError: the base cannot be read, or the merged scenario's bad field.
    """
    try:
        doc = yaml.safe_load(base.read_text())
    except (OSError, yaml.YAMLError) as e:
        raise InputError('scenario', f'cannot read {base}: {e}'.splitlines()[0]) from e
    doc = merge(doc, {k: v for k, v in line.items() if k != 'id'})
    doc.update(over)
    return parse_scenario(doc, base.parent, f"{base.name} + {line.get('id', 'candidate')}")


def simulate_candidate(scenario: Scenario, settings: EpisodeSettings,
                       sim: SimSettings = SimSettings()) -> tuple[EpisodeReport, Any, Any]:
    """
    Simulate a scenario held by the node's cycle on the rig.

    The cycle has the scenario's friction margin; a finger pushed past its URDF limit
    (the object knocked away) is input the node refuses: it sends nothing new and the
    driver holds the last command.

    Returns:
        The episode's report, the rig at its end and the node's controller.
    """
    setup, rig = simulated(scenario, settings, GraspSetup.from_scenario(scenario), sim=sim)
    node = node_controller(setup, scenario, rig, margin=scenario.friction.margin)

    def guarded(reading):
        try:
            return node(reading)
        except InputError:
            return None
    return run_episode(rig, guarded, settings), rig, node.controller


def certified_forces(controller) -> list[np.ndarray] | None:
    """Return the controller's last certified contact forces on the object, base axes [N]."""
    last = controller.last
    if last is None or last.solution is None or last.maps is None:
        return None
    wrenches = last.wrenches if last.wrenches is not None else last.solution.wrenches
    if wrenches is None:
        return None
    return [R @ np.asarray(w)[:3] for R, w in zip(last.maps.rotations, wrenches)]


def _draw(rig, controller, picture: str) -> str:
    """Write the picture of the rig's state; return the words that say where (or why not)."""
    from grasp_torque_opt.sim.render import CAPTION, render_grasp, RenderUnavailable

    try:
        written = render_grasp(rig, picture, certified_forces(controller))
    except RenderUnavailable as e:
        return f'picture not written, offscreen rendering is unavailable ({e})'
    except OSError as e:
        return f'picture not written, cannot write {picture}: {e.strerror}'
    return f'picture {written.resolve()} ({CAPTION})'


def run(args: argparse.Namespace, base: Path, settings: EpisodeSettings,
        sim: SimSettings) -> int:
    """
    Simulate the best candidate of ``args.plan`` / ``args.scores``; print; return the exit.

    Exit 0 held, 1 not held. Raises InputError on bad files (the caller's exit 2).
    """
    best, line = best_candidate(args.plan, args.scores)
    report, rig, controller = simulate_candidate(candidate_scenario(base, line), settings, sim)
    drawn = 'no picture' if args.no_picture else _draw(rig, controller, args.picture)
    capacity = best.get('capacity')
    capacity = 'capacity not scored' if capacity is None else f'capacity {capacity:.3f}'
    print(f"best: {best.get('id', 'line ' + str(best['line']))} (rank {best['rank']} of "
          f"{args.scores}, {capacity}); simulated {report.time:.1f} s with the node's "
          f"torques: {'held' if report.held else 'NOT held'}, drift "
          f'{1e3 * report.max_drift:.3g} mm (limit {1e3 * settings.drift_limit:g} mm), '
          f'rotation {np.degrees(report.max_rotation):.3g} deg; {drawn}', flush=True)
    return 0 if report.held else 1
