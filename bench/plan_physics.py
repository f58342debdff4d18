# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Planned grasps in physics: does the ranking, and each prediction, hold in MuJoCo.

Usage: .venv/bin/python bench/plan_physics.py [--count 9] [--per-band 2] [--seed 0]
       [--margin K] [--unfiltered] [--out bench/results/plan_physics.json]

Per object (a sphere, a box, a cylinder of 0.15 kg on the bundled Allegro): plan
``--count`` candidates (``plan_grasps``), score them (``score_batch``, full metrics),
rank by capacity and take ``--per-band`` from the top, the middle and the bottom.
Each is simulated with the node's cycle (ros/sim_plan.simulate_candidate, as
``grasp-torque-sim --plan PLAN --scores SCORES`` simulates the best) under the
grasp benchmarks' protocol: gravity off, a force of the object's weight on its
centre along +x, -x, +y, -y, +z, -z in turn (one episode of 2 s each after 0.3 s
of settling), the node told that load. Success: the object moves < 5 cm and turns
< 15 deg; strict: < 2 mm and < 2 deg. The prediction of an episode: the candidate
has an axis capacity along the force (certified) of at least the force.

``--unfiltered`` plans as before issue 38 (uniform orientations, every candidate that
touches kept, held or not): the population whose capacities of grasps that cannot
hold their own load the prediction must get right.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
import platform
import subprocess
import sys
import tempfile
import time

from grasp_torque_opt.core.object_geometry import ObjectShape
from grasp_torque_opt.methods.engines import score_batch
from grasp_torque_opt.methods.plan import plan_grasps, PlanSettings
from grasp_torque_opt.methods.ranking import rank
from grasp_torque_opt.methods.score import ScoreJob
from grasp_torque_opt.ros.sim_plan import candidate_scenario, simulate_candidate
from grasp_torque_opt.sim.episode import EpisodeSettings
import numpy as np
import yaml

ROOT = Path(__file__).resolve().parent.parent
SCENARIO = ROOT / 'config' / 'allegro_right.yaml'
MASS = 0.15
OBJECTS = {'sphere': [0.04], 'box': [0.05, 0.05, 0.07], 'cylinder': [0.03, 0.10]}
DIRECTIONS = {'+Fx': (0, 1.0), '-Fx': (0, -1.0), '+Fy': (1, 1.0), '-Fy': (1, -1.0),
              '+Fz': (2, 1.0), '-Fz': (2, -1.0)}
LOOSE, STRICT = (0.05, math.radians(15.0)), (2e-3, math.radians(2.0))


def episode(line: dict, force: np.ndarray, duration: float = 2.0):
    """Simulate a plan line holding the object against ``force`` (gravity off); the report."""
    scenario = candidate_scenario(SCENARIO, line, gravity=[0.0, 0.0, 0.0], load={
        'external_wrench': [*force.tolist(), 0.0, 0.0, 0.0]})
    settings = EpisodeSettings(duration=duration, drift_limit=LOOSE[0],
                               object_force=tuple(float(f) for f in force))
    report, _, _ = simulate_candidate(scenario, settings)
    return report


def bands(ranked: list[dict], k: int) -> dict[str, list[dict]]:
    """Top, median and bottom ``k`` of a ranking."""
    n = len(ranked)
    mid = max(0, n // 2 - k // 2)
    return {'top': ranked[:k], 'median': ranked[mid:mid + k], 'bottom': ranked[max(0, n - k):]}


def run_object(kind: str, count: int, per_band: int, seed: int, unfiltered: bool = False
               ) -> dict:
    shape = ObjectShape(kind, np.array(OBJECTS[kind]))
    extra = {'orientation': 'random', 'hold_margin': None} if unfiltered else {}
    plan = plan_grasps(SCENARIO, PlanSettings(count=count, seed=seed, **extra), shape=shape,
                       mass=MASS)
    by_id = {c['id']: c for c in plan.candidates}
    records = score_batch(ScoreJob.from_file(SCENARIO), plan.candidates, engine='serial')
    for r, c in zip(records, plan.candidates):
        r['id'] = c['id']
    ranked = rank(records, 'capacity')
    weight = MASS * 9.81
    rows, episodes = {}, []
    for band, chosen in bands(ranked, per_band).items():
        for rec in chosen:
            for name, (axis, sign) in DIRECTIONS.items():
                force = np.zeros(3)
                force[axis] = sign * weight
                rep = episode(by_id[rec['id']], force)
                cap = (rec.get('capacities') or {}).get(name)
                # The axis capacity is that direction's own LP (the status is the
                # candidate's own load's, the weight along base +x: not this one).
                predicted = cap is not None and cap >= weight
                loose = rep.max_drift < LOOSE[0] and rep.max_rotation < LOOSE[1]
                strict = rep.max_drift < STRICT[0] and rep.max_rotation < STRICT[1]
                episodes.append({'object': kind, 'band': band, 'id': rec['id'],
                                 'rank': ranked.index(rec) + 1, 'status': rec['status'],
                                 'direction': name, 'capacity_N': cap,
                                 'predicted': predicted, 'held': loose, 'strict': strict,
                                 'max_drift_m': rep.max_drift,
                                 'max_rotation_deg': math.degrees(rep.max_rotation)})
        mine = [e for e in episodes if e['band'] == band]
        rows[band] = {'candidates': len(chosen), 'episodes': len(mine),
                      'held': sum(e['held'] for e in mine),
                      'strict': sum(e['strict'] for e in mine),
                      'agree': sum(e['held'] == e['predicted'] for e in mine),
                      'agree_strict': sum(e['strict'] == e['predicted'] for e in mine)}
    feasible = sum(r['status'] == 'optimal' for r in records)
    return {'object': kind, 'planned': len(plan.candidates), 'iks': plan.attempts,
            'feasible': feasible, 'bands': rows, 'episodes': episodes}


def table(results: list[dict]) -> str:
    lines = ['| object | planned (IKs) | feasible by score | band | candidates | held (5 cm, '
             '15 deg) | strict (2 mm, 2 deg) | prediction agrees (5 cm / 2 mm) |',
             '|---|---|---|---|---:|---:|---:|---:|']
    for res in results:
        for band, row in res['bands'].items():
            n = row['episodes']
            lines.append(f"| {res['object']} | {res['planned']} ({res['iks']}) | "
                         f"{res['feasible']} | {band} | {row['candidates']} | "
                         f"{row['held']}/{n} | {row['strict']}/{n} | {row['agree']}/{n} / "
                         f"{row['agree_strict']}/{n} |")
    return '\n'.join(lines)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    p.add_argument('--count', type=int, default=9)
    p.add_argument('--per-band', type=int, default=2)
    p.add_argument('--seed', type=int, default=0)
    p.add_argument('--objects', default='sphere,box,cylinder')
    p.add_argument('--out')
    p.add_argument('--unfiltered', action='store_true',
                   help='plan uniform orientations and keep every candidate that touches '
                   '(the planner before issue 38)')
    p.add_argument('--margin', type=float, default=0.0,
                   help="the friction margin k of the scenario: the plan's scores, the "
                        "capacities predicted and the node's torques all use it")
    args = p.parse_args()
    if args.margin:
        global SCENARIO
        doc = yaml.safe_load(SCENARIO.read_text())
        doc.setdefault('friction', {})['margin'] = args.margin
        margined = Path(tempfile.mkdtemp()) / SCENARIO.name
        margined.write_text(yaml.safe_dump(doc))
        SCENARIO = margined
    t0 = time.time()
    results = [run_object(k, args.count, args.per_band, args.seed, args.unfiltered)
               for k in args.objects.split(',')]
    commit = subprocess.run(['git', 'rev-parse', '--short', 'HEAD'], capture_output=True,
                            text=True, cwd=ROOT).stdout.strip()
    print(f'commit {commit}; {platform.processor() or platform.machine()}, '
          f'{platform.node()}; {time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}; '
          f'{time.time() - t0:.0f} s')
    print(table(results))
    episodes = [e for r in results for e in r['episodes']]
    for key in ('held', 'strict'):
        agree = sum(e[key] == e['predicted'] for e in episodes)
        print(f"agreement ({'5 cm, 15 deg' if key == 'held' else '2 mm, 2 deg'}): {agree} "
              f'of {len(episodes)} episodes ({100 * agree / max(1, len(episodes)):.1f}%)')
    for e in episodes:
        if e['strict'] != e['predicted']:
            cap = 'none' if e['capacity_N'] is None else f"{e['capacity_N']:.3g} N"
            print(f"  disagree: {e['object']} {e['id']} (rank {e['rank']}, {e['status']}) "
                  f"{e['direction']}: capacity {cap}, predicted "
                  f"{'hold' if e['predicted'] else 'drop'}, simulated drift "
                  f"{1e3 * e['max_drift_m']:.3g} mm, rotation {e['max_rotation_deg']:.3g} deg")
    if args.out:
        Path(args.out).write_text(json.dumps(results, indent=1))
    return 0


if __name__ == '__main__':
    sys.exit(main())
