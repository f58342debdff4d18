# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
tau-qp-adaptive against the fixed polygons and the exact SOCP: excess, bounds, time.

Usage: .venv/bin/python bench/adaptive.py [--grasps 200] [--seed 0] [--repeats 7]
       [--gap 1e-3] [--steps 500] [--out bench/results/adaptive.json]

Cases: the paper's planar case (config/planar_two_finger.yaml, N = 3) and the
seeded Allegro grasp set of bench/grasps.py (N = 8). Per grasp, G and J are
computed once and every method is timed as solve(setup, method, maps=maps,
solver=...) (build, solve, certify; solvers reused across grasps), the median of
``repeats`` calls:

- ``own N`` (planar 3, Allegro 8) and ``N=32``, DAQP and ProxSuite: the fixed
  inscribed polygon (tau-qp);
- ``socp``: the exact cone, Clarabel (the reference optimum E);
- ``adaptive``: tau-qp-adaptive with its default settings (DAQP inside).

A third case is the node's: the bundled Allegro grasp with the fingers walking
by 1 mrad per cycle and the load turning once in ``steps`` cycles, each cycle
timed once: tau-qp-adaptive warm (each cycle starts at the last answer's
directions) against the tau-QP with DAQP and ProxSuite warm (the node's default).

Reported: the adaptive torque's excess over E, ||tau|| / ||tau_E|| - 1 (every
case has W = I), its certified gap, and whether its bounds bracket E (lower <=
E <= upper up to 1e-9 relative: the SOCP is only as exact as its tolerance);
QPs and rounds; per method the median and p99 over the grasps of the per-grasp
times, and the ratio adaptive / own N per grasp (of the medians, and of each
grasp's fastest call, which a loaded machine touches least). BLAS runs
single-threaded, as in the node.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path
import sys
import time

import numpy as np

# The imports below need bench/ on sys.path for its sibling modules, so they follow
# code (E402) and stay out of the alphabetical block above (I100).
sys.path.insert(0, str(Path(__file__).resolve().parent))
from cycle import machine, report, ROOT  # noqa: E402, I100
from grasp_torque_opt.backends import make_solver, single_threaded_math  # noqa: E402
from grasp_torque_opt.core.grasp_setup import GraspSetup  # noqa: E402
from grasp_torque_opt.methods.adaptive import AdaptiveSettings, Refiner  # noqa: E402
from grasp_torque_opt.methods.dispatch import solve  # noqa: E402
from grasps import allegro_grasps, blas_threads  # noqa: E402

PLANAR = ROOT / 'config' / 'planar_two_finger.yaml'
SCENARIO_ALLEGRO = ROOT / 'config' / 'allegro_right.yaml'
#: Relative slack of the bracket check lower <= E <= upper (Clarabel's own accuracy).
BRACKET = 1e-9
#: Timed columns: the case's own N, then N = 32, per backend; the SOCP; the method.
TIMED = ('own N daqp', 'own N proxsuite', 'N=32 daqp', 'N=32 proxsuite', 'socp', 'adaptive')


def _sides(setup: GraspSetup, n: int) -> GraspSetup:
    return dataclasses.replace(setup, friction=dataclasses.replace(setup.friction, sides=n))


def _median_time(fn, repeats: int, fastest: list | None = None) -> float:
    """Return the median of ``repeats`` calls [s], appending their fastest to ``fastest``."""
    samples = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - t0)
    if fastest is not None:
        fastest.append(min(samples))
    return float(np.median(samples))


def one_case(setups: list[GraspSetup], repeats: int, settings: AdaptiveSettings,
             fixed_sides: tuple[int, int]) -> dict:
    """Every method on every grasp of one case (JSON-able)."""
    daqp, prox = make_solver('daqp'), make_solver('proxsuite')
    refiner = Refiner(settings)
    rows, times = [], {k: [] for k in TIMED}
    fastest = {'own N daqp': [], 'adaptive': []}  # least touched by a shared machine
    counts = {'optimal': 0, 'infeasible': 0, 'failed': 0}
    for setup in setups:
        maps = setup.maps()
        exact = solve(setup, 'socp', maps=maps)
        ada = solve(setup, 'tau-qp-adaptive', maps=maps, refiner=refiner, solver=prox,
                    fallback=daqp)
        counts[ada.status] += 1
        fixed = {}
        for n, col in zip(fixed_sides, ('own N', 'N=32')):
            s = _sides(setup, n)
            fixed[n] = solve(s, maps=maps, solver=daqp)
            times[f'{col} daqp'].append(_median_time(
                lambda: solve(s, maps=maps, solver=daqp), repeats, fastest.get(f'{col} daqp')))
            times[f'{col} proxsuite'].append(
                _median_time(lambda: solve(s, maps=maps, solver=prox), repeats))
        times['socp'].append(_median_time(lambda: solve(setup, 'socp', maps=maps), repeats))
        times['adaptive'].append(_median_time(
            lambda: solve(setup, 'tau-qp-adaptive', maps=maps, refiner=refiner, solver=prox,
                          fallback=daqp), repeats, fastest['adaptive']))
        if not (exact.optimal and ada.optimal):
            continue
        E, b = exact.torque_norm, ada.bounds
        rows.append({
            'excess': ada.torque_norm / E - 1.0,
            'fixed_excess': {str(n): (fixed[n].torque_norm / E - 1.0) if fixed[n].optimal
                             else None for n in fixed_sides},
            'gap': b.gap, 'rounds': b.rounds, 'qp_solves': b.qp_solves, 'source': b.source,
            'lower_ok': b.lower is not None and b.lower <= E * (1 + BRACKET),
            'upper_ok': b.upper >= E * (1 - BRACKET),
        })
    t = {k: np.asarray(v) for k, v in times.items()}
    ratio = t['adaptive'] / t['own N daqp']
    ratio_prox = t['adaptive'] / t['own N proxsuite']
    ratio_fastest = np.asarray(fastest['adaptive']) / np.asarray(fastest['own N daqp'])
    ex = np.array([r['excess'] for r in rows])
    gaps = np.array([np.inf if r['gap'] is None else r['gap'] for r in rows])
    qps = np.array([r['qp_solves'] for r in rows])

    def stats(a: np.ndarray) -> dict:
        return {'median': float(np.median(a)), 'p99': float(np.percentile(a, 99)),
                'max': float(a.max())}

    return {
        'grasps': len(setups), 'counts': counts, 'compared': len(rows),
        'excess': {**stats(ex), 'min': float(ex.min())},
        'gap': stats(gaps),
        'within_0.1%': int(np.sum(ex <= 1e-3)),
        'bracket_violations': int(sum(not (r['lower_ok'] and r['upper_ok']) for r in rows)),
        'qp_solves': {'median': float(np.median(qps)), 'max': int(qps.max()),
                      'histogram': np.bincount(qps).tolist()},
        'sources': {s: sum(r['source'] == s for r in rows)
                    for s in ('refined', 'circumscribed', 'polygon')},
        'fixed_excess': {str(n): stats(np.array([r['fixed_excess'][str(n)] for r in rows
                                                 if r['fixed_excess'][str(n)] is not None]))
                         for n in fixed_sides},
        'times_s': {k: {'median': float(np.median(v)), 'p99': float(np.percentile(v, 99))}
                    for k, v in t.items()},
        'ratio_to_n8_daqp': {'median': float(np.median(ratio)),
                             'p99': float(np.percentile(ratio, 99)), 'max': float(ratio.max())},
        'ratio_to_n8_proxsuite': {'median': float(np.median(ratio_prox)),
                                  'p99': float(np.percentile(ratio_prox, 99))},
        'fastest_ratio_to_n8_daqp': {'median': float(np.median(ratio_fastest)),
                                     'p99': float(np.percentile(ratio_fastest, 99))},
        'faster_than_socp': int(np.sum(t['adaptive'] < t['socp'])),
    }


def walking(setup: GraspSetup, steps: int, seed: int = 0) -> list[GraspSetup]:
    """Return the grasp with the fingers walking by 1 mrad per cycle, the load turning once."""
    rng = np.random.default_rng(seed)
    out, q = [], setup.q.copy()
    weight = float(np.linalg.norm(setup.external_wrench[:3]))
    for k in range(steps):
        q = q.copy()
        q[setup.hand.idx_q] += rng.normal(scale=1e-3, size=setup.hand.m)
        th = 2 * np.pi * k / steps
        w = setup.external_wrench.copy()
        w[:3] = weight * np.array([np.cos(th), 0.3 * np.sin(th), np.sin(th)])
        out.append(dataclasses.replace(setup, q=q, external_wrench=w))
    return out


def moving_case(steps: int, settings: AdaptiveSettings) -> dict:
    """Time the node's case warm (JSON-able), with the exact optimum on every tenth cycle."""
    seq = walking(GraspSetup.from_file(SCENARIO_ALLEGRO), steps)
    variants = {'adaptive warm': None, 'tau-qp daqp warm': make_solver('daqp', warm_start=True),
                'tau-qp proxsuite warm': make_solver('proxsuite', warm_start=True)}
    fallback = make_solver('daqp')
    refiner = Refiner(dataclasses.replace(settings, warm_start=True))
    times = {k: [] for k in variants}
    gaps, excess, qps, failed = [], [], [], 0
    for k, setup in enumerate(seq):
        maps = setup.maps()
        for name, solver in variants.items():
            t0 = time.perf_counter()
            if solver is None:
                sol = solve(setup, 'tau-qp-adaptive', maps=maps, refiner=refiner,
                            solver=variants['tau-qp proxsuite warm'], fallback=fallback)
            else:
                sol = solve(setup, maps=maps, solver=solver, fallback=fallback)
            times[name].append(time.perf_counter() - t0)
            if solver is None:
                failed += not sol.optimal
                if sol.optimal:
                    gaps.append(np.inf if sol.bounds.gap is None else sol.bounds.gap)
                    qps.append(sol.bounds.qp_solves)
                    if k % 10 == 0:
                        exact = solve(setup, 'socp', maps=maps)
                        if exact.optimal:
                            excess.append(sol.torque_norm / exact.torque_norm - 1.0)
    skip = 20  # warm-up
    t = {k: np.asarray(v[skip:]) for k, v in times.items()}
    return {'steps': steps, 'failed': failed,
            'gap_max': float(max(gaps)), 'qp_solves_mean': float(np.mean(qps)),
            'excess_max': float(max(excess)), 'excess_checked': len(excess),
            'warm_solves': refiner.warm_solves, 'warm_fallbacks': refiner.warm_fallbacks,
            'times_s': {k: {'median': float(np.median(v)), 'p99': float(np.percentile(v, 99)),
                            'max': float(v.max())} for k, v in t.items()}}


def run(grasps: int = 200, seed: int = 0, repeats: int = 7, gap: float = 1e-3,
        steps: int = 500) -> dict:
    """Every case (JSON-able)."""
    settings = AdaptiveSettings(gap_tolerance=gap)
    planar = GraspSetup.from_file(PLANAR)
    return {'machine': machine(), 'blas_threads': blas_threads(), 'seed': seed,
            'repeats': repeats, 'settings': dataclasses.asdict(settings),
            'cases': {'planar (N=3)': one_case([planar], repeats, settings,
                                               (planar.friction.sides, 32)),
                      f'allegro, {grasps} grasps (N=8)': one_case(
                          allegro_grasps(grasps, seed), repeats, settings, (8, 32))},
            'moving': moving_case(steps, settings)}


def table(results: dict) -> str:
    """Markdown: accuracy and bounds, then times."""
    lines = ['| case | excess median | max | certified gap max | within 0.1% | '
             'bounds bracket E | QPs median / max | fixed N excess median / max |',
             '|---|---:|---:|---:|---:|---:|---:|---|']
    for name, c in results['cases'].items():
        fixed = '; '.join(f"N={n}: {100 * v['median']:.2f}% / {100 * v['max']:.2f}%"
                          for n, v in c['fixed_excess'].items())
        lines.append(
            f"| {name} | {100 * c['excess']['median']:.2g}% | {100 * c['excess']['max']:.2g}% "
            f"| {100 * c['gap']['max']:.2g}% | {c['within_0.1%']}/{c['compared']} | "
            f"{c['compared'] - c['bracket_violations']}/{c['compared']} | "
            f"{c['qp_solves']['median']:.0f} / {c['qp_solves']['max']} | {fixed} |")
    lines += ['', '| case | ' + ' | '.join(TIMED) + ' | adaptive / own N daqp | '
              'fastest / fastest | adaptive / own N proxsuite | faster than socp |',
              '|---|' + '---:|' * (len(TIMED) + 4)]
    for name, c in results['cases'].items():
        ts = c['times_s']
        cells = [f"{1e6 * ts[k]['median']:.0f} / {1e6 * ts[k]['p99']:.0f}" for k in TIMED]
        r, rp, rf = (c['ratio_to_n8_daqp'], c['ratio_to_n8_proxsuite'],
                     c['fastest_ratio_to_n8_daqp'])
        lines.append(f'| {name} | ' + ' | '.join(cells) +
                     f" | {r['median']:.2f} (p99 {r['p99']:.2f}) | {rf['median']:.2f} "
                     f"(p99 {rf['p99']:.2f}) | {rp['median']:.2f} "
                     f"(p99 {rp['p99']:.2f}) | {c['faster_than_socp']}/{c['grasps']} |")
    lines.append('')
    lines.append("Times: median / p99 over the grasps of each grasp's median [us] of "
                 "solve(); own N: the scenario's polygon (planar 3, Allegro 8); fastest / "
                 "fastest: the ratio of each grasp's fastest calls, adaptive over own N "
                 'daqp (the figure a shared machine touches least).')
    mv = results.get('moving')
    if mv:
        lines += ['', f"Moving Allegro grasp, {mv['steps']} cycles, warm: adaptive gap max "
                  f"{100 * mv['gap_max']:.2g}%, excess over the SOCP max "
                  f"{100 * mv['excess_max']:.2g}% ({mv['excess_checked']} cycles checked), "
                  f"{mv['qp_solves_mean']:.2f} QPs per cycle, {mv['warm_fallbacks']} of "
                  f"{mv['warm_solves']} warm starts redone cold, {mv['failed']} failed.", '',
                  '| per cycle [us] | median | p99 | max |', '|---|---:|---:|---:|']
        for k, v in mv['times_s'].items():
            lines.append(f"| {k} | {1e6 * v['median']:.0f} | {1e6 * v['p99']:.0f} | "
                         f"{1e6 * v['max']:.0f} |")
    return '\n'.join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--grasps', type=int, default=200)
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--repeats', type=int, default=7)
    parser.add_argument('--gap', type=float, default=1e-3)
    parser.add_argument('--steps', type=int, default=500, help='cycles of the moving case')
    parser.add_argument('--out', type=Path, help='write the results as JSON here')
    args = parser.parse_args()
    single_threaded_math()
    res = run(args.grasps, args.seed, args.repeats, args.gap, args.steps)
    report(res, table(res), args.out,
           f"{args.grasps} grasps, seed {args.seed}; threads: {res['blas_threads']}")


if __name__ == '__main__':
    main()
