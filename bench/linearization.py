# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
What the polygon costs: torque-norm excess over the exact cone, per number of sides N.

Usage: .venv/bin/python bench/linearization.py [--grasps 200] [--seed 0]
       [--sides 3 4 6 8 12 16 32] [--backend proxsuite] [--out bench/results/linearization.json]

On the seeded Allegro grasp set of bench/grasps.py (kept feasible for the
scenario's N = 8), per grasp: the exact-cone optimum (solve(setup, "socp"),
Clarabel) and, for each N, solve(setup with friction.sides = N, backend=B),
both certified by solve() itself, G and J computed once per grasp. Reported
per N, in percent: the median, p90 and max over the grasps of
||tau_N|| / ||tau_exact|| - 1 (grasps where both are optimal), and the counts of
grasps the polygon makes infeasible (solve() has the HiGHS LP confirm every
infeasible verdict) or that failed. The inscribed N-gon is inside the cone, so
the excess is >= 0 up to solver tolerance, and a polygon can lose grasps the
cone holds; the polygons are nested only when one N divides the other
(3 | 6 | 12, 4 | 8 | 16 | 32), so the counts need not fall monotonically.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path
import sys

import numpy as np

# The imports below need bench/ on sys.path for its sibling modules, so they follow
# code (E402) and stay out of the alphabetical block above (I100).
sys.path.insert(0, str(Path(__file__).resolve().parent))
from cycle import machine, report  # noqa: E402, I100
from grasp_torque_opt.backends import make_solver  # noqa: E402
from grasp_torque_opt.methods.dispatch import solve  # noqa: E402
from grasps import allegro_grasps, blas_threads  # noqa: E402

SIDES = (3, 4, 6, 8, 12, 16, 32)


def run(grasps: int = 200, seed: int = 0, sides: tuple[int, ...] = SIDES,
        backend: str = 'proxsuite') -> dict:
    """Excess and infeasible counts per N (JSON-able)."""
    setups = allegro_grasps(grasps, seed)
    solver = make_solver(backend)
    exact_status = {'optimal': 0, 'infeasible': 0, 'failed': 0}
    per = {n: {'optimal': 0, 'infeasible': 0, 'failed': 0, 'excess': [],
               'fail_examples': []} for n in sides}
    for i, setup in enumerate(setups):
        maps = setup.maps()
        exact = solve(setup, 'socp', maps=maps)
        exact_status[exact.status] += 1
        for n in sides:
            s = dataclasses.replace(setup, friction=dataclasses.replace(setup.friction, sides=n))
            sol = solve(s, maps=maps, solver=solver)
            rec = per[n]
            rec[sol.status] += 1
            if sol.status == 'failed' and len(rec['fail_examples']) < 5:
                rec['fail_examples'].append({'grasp': i, 'why': sol.message})
            if sol.optimal and exact.optimal:
                rec['excess'].append(sol.torque_norm / exact.torque_norm - 1.0)
    out = {'machine': machine(), 'blas_threads': blas_threads(), 'grasps': grasps, 'seed': seed,
           'backend': backend, 'exact': exact_status, 'sides': {}}
    for n, rec in per.items():
        e = np.asarray(rec.pop('excess'))
        rec['excess_n'] = int(e.size)
        if e.size:
            rec.update(excess_median=float(np.median(e)), excess_p90=float(np.percentile(e, 90)),
                       excess_max=float(e.max()), excess_min=float(e.min()))
        out['sides'][str(n)] = rec
    return out


def table(results: dict) -> str:
    """Markdown table: one row per N."""
    ex = results['exact']
    lines = [f"exact cone (SOCP): optimal {ex['optimal']}, infeasible {ex['infeasible']}, "
             f"failed {ex['failed']}; polygon backend {results['backend']}", '',
             '| N | excess median | p90 | max | n | infeasible | failed |',
             '|---:|---:|---:|---:|---:|---:|---:|']
    for n, r in results['sides'].items():
        if r['excess_n']:
            cols = (f"{100 * r['excess_median']:.2f}% | {100 * r['excess_p90']:.2f}% | "
                    f"{100 * r['excess_max']:.2f}%")
        else:
            cols = '- | - | -'
        lines.append(f"| {n} | {cols} | {r['excess_n']} | {r['infeasible']} | {r['failed']} |")
    return '\n'.join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--grasps', type=int, default=200)
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--sides', type=int, nargs='+', default=list(SIDES))
    parser.add_argument('--backend', default='proxsuite')
    parser.add_argument('--out', type=Path, help='write the results as JSON here')
    args = parser.parse_args()
    res = run(args.grasps, args.seed, tuple(args.sides), args.backend)
    report(res, table(res), args.out,
           f"{args.grasps} grasps, seed {args.seed}; threads: {res['blas_threads']}")


if __name__ == '__main__':
    main()
