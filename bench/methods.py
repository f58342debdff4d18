# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The tau-QP against the reference methods on seeded random loads.

Usage: .venv/bin/python bench/methods.py [--loads 200] [--seed 0] [--json FILE]

For each bundled scenario, the grasp is kept and the load is drawn at random:
a force of random direction with 0.3 to 2 times the scenario's magnitude, plus
a random moment (5% of that force times 0.05 m, i.e. a small off-centre load).
Per method: loads solved, infeasible, failed, the median solve time; and the
distribution of the tau-QP's ||tau||_2 reduction against the force-space
method and of its excess over the exact-cone optimum.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path
import sys

import numpy as np

# The imports below need bench/ on sys.path for its sibling modules, so they follow
# code (E402) and stay out of the alphabetical block above (I100).
sys.path.insert(0, str(Path(__file__).resolve().parent))
from cycle import machine, ROOT, SCENARIOS  # noqa: E402, I100
from grasp_torque_opt.backends.proxsuite import TauQPSolver  # noqa: E402
from grasp_torque_opt.core.grasp_setup import GraspSetup  # noqa: E402
from grasp_torque_opt.methods.dispatch import METHODS, solve  # noqa: E402


def random_loads(setup: GraspSetup, count: int, rng: np.random.Generator) -> np.ndarray:
    """Seeded loads around the scenario's magnitude, shape (count, 6)."""
    scale = max(np.linalg.norm(setup.external_wrench[:3]), 0.5)
    d = rng.normal(size=(count, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    force = d * scale * rng.uniform(0.3, 2.0, size=(count, 1))
    moment = rng.normal(size=(count, 3)) * 0.05 * scale * 0.05
    return np.hstack((force, moment))


def stats(x: list[float]) -> dict:
    if not x:
        return {'n': 0}
    a = np.asarray(x)
    return {'n': len(a), 'median': float(np.median(a)), 'p90': float(np.percentile(a, 90)),
            'min': float(a.min()), 'max': float(a.max())}


def run(setup: GraspSetup, loads: np.ndarray) -> dict:
    maps = setup.maps()
    solver = TauQPSolver()
    counts = {m: {'optimal': 0, 'infeasible': 0, 'failed': 0} for m in METHODS}
    times = {m: [] for m in METHODS}
    reduction, excess, disagreements = [], [], 0
    for w in loads:
        s = dataclasses.replace(setup, external_wrench=w)
        sols = {m: solve(s, m, maps=maps, solver=solver) for m in METHODS}
        for m, sol in sols.items():
            counts[m][sol.status] += 1
            times[m].append(sol.solve_time_s)
        ours, force, exact = sols['tau-qp'], sols['force-qp'], sols['socp']
        if ours.optimal and force.optimal:
            reduction.append(1.0 - ours.torque_norm / force.torque_norm)
        if ours.optimal and exact.optimal:
            excess.append(ours.torque_norm / exact.torque_norm - 1.0)
        if (ours.status == 'infeasible') != (force.status == 'infeasible'):
            disagreements += 1
    return {'counts': counts,
            'solve_time_median_s': {m: float(np.median(t)) for m, t in times.items()},
            'reduction_vs_force_qp': stats(reduction),
            'excess_over_exact': stats(excess),
            'feasibility_disagreements_tau_vs_force': disagreements}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--loads', type=int, default=200)
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--json', type=Path)
    args = parser.parse_args()
    out = {'machine': machine(), 'loads': args.loads, 'seed': args.seed, 'scenarios': {}}
    print(f"machine: {out['machine']['cpu']}, {out['machine']['cores']} cores; "
          f"{out['machine']['date']}; {args.loads} loads, seed {args.seed}")
    for name in SCENARIOS:
        setup = GraspSetup.from_file(ROOT / 'config' / name)
        res = run(setup, random_loads(setup, args.loads, np.random.default_rng(args.seed)))
        out['scenarios'][name] = res
        print(f'\n{name}')
        for m in METHODS:
            c = res['counts'][m]
            print(f"  {m:<9} optimal {c['optimal']:>4}  infeasible {c['infeasible']:>4}  "
                  f"failed {c['failed']:>3}  median solve "
                  f"{1e3 * res['solve_time_median_s'][m]:7.3f} ms")
        for key, label in (('reduction_vs_force_qp', '||tau|| reduction vs force QP'),
                           ('excess_over_exact', '||tau|| excess over exact SOCP')):
            st = res[key]
            if st['n']:
                print(f"  {label}: median {100 * st['median']:.2f}%, p90 {100 * st['p90']:.2f}%,"
                      f" max {100 * st['max']:.2f}% (n = {st['n']})")
        print(f'  tau-QP and force QP disagree on feasibility: '
              f"{res['feasibility_disagreements_tau_vs_force']}")
    if args.json:
        args.json.write_text(json.dumps(out, indent=2))


if __name__ == '__main__':
    main()
