# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Batch scoring throughput: ``grasp-torque-opt score``'s candidates per second on the Allegro.

Usage: .venv/bin/python bench/score.py [--count 4000] [--seed 0] [--workers 2]
       [--backends daqp proxsuite] [--dask] [--out bench/results/score.json]

The batch is bench/candidates.py's (JSON Lines of scenario overrides of
config/allegro_right.yaml: joints moved by up to 0.08 rad, random loads of 0.3
to 2 ball weights, unfiltered), scored by grasp_torque_opt.methods.score as the
CLI scores it: each line parsed and validated as a scenario, bound to the hand,
solved (tau-QP) and certified; ``full`` adds the load capacity and the 12 axis
capacities (13 certified LPs per candidate). Per backend and metrics:

- serial: this process, one solver (the engine ``serial``);
- pool: ``--workers`` spawned processes (the engine ``processes``), BLAS
  single-threaded in each. "with start-up" is the whole call (pool start,
  imports, each worker binding the hand); "steady" subtracts the start-up,
  measured as the same call on a 2-candidate batch;
- with ``--dask``: a local Dask cluster of ``--workers`` processes (the engine
  ``dask``), the whole call including the cluster's start.

The issue's targets: >= 5,000 candidates/s on 2 cores with the fastest backend
(``basic`` metrics), >= 1,000/s with full metrics.
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys
import time

# The imports below need bench/ on sys.path for its sibling modules, so they follow
# code (E402).
sys.path.insert(0, str(Path(__file__).resolve().parent))
from candidates import candidate_lines  # noqa: E402
from cycle import machine, report  # noqa: E402
from grasp_torque_opt.backends import single_threaded_math  # noqa: E402
from grasp_torque_opt.methods.score import score_batch, ScoreJob  # noqa: E402
from grasps import blas_threads, SCENARIO  # noqa: E402

TARGETS = {'basic': 5000.0, 'full': 1000.0}


def timed(job, lines, **kw) -> tuple[float, list]:
    t0 = time.perf_counter()
    records = score_batch(job, lines, **kw)
    return time.perf_counter() - t0, records


def run(count: int = 4000, seed: int = 0, workers: int = 2,
        backends: tuple[str, ...] = ('daqp', 'proxsuite'), dask: bool = False) -> dict:
    """Throughput per backend, metrics and engine (JSON-able)."""
    single_threaded_math()
    lines = list(enumerate(candidate_lines(count, seed), 1))
    out = {'machine': machine(), 'blas_threads': blas_threads(), 'count': count, 'seed': seed,
           'workers': workers, 'targets': TARGETS, 'rows': []}
    for backend in backends:
        for metrics in ('basic', 'full'):
            job = ScoreJob.from_file(SCENARIO, backend=backend, metrics=metrics)
            n = count if metrics == 'basic' else max(count // 2, 1)  # full: 13 LPs each
            batch = lines[:n]
            timed(job, batch[:50], engine='serial')  # the first binds the hand
            t_serial, records = timed(job, batch, engine='serial')
            t_start, _ = timed(job, batch[:2], engine='processes', workers=workers, chunk=1)
            t_pool, _ = timed(job, batch, engine='processes', workers=workers)
            row = {'backend': backend, 'metrics': metrics, 'candidates': n,
                   'optimal': sum(r['status'] == 'optimal' for r in records),
                   'infeasible': sum(r['status'] == 'infeasible' for r in records),
                   'serial_per_s': n / t_serial, 'pool_per_s_with_startup': n / t_pool,
                   'pool_startup_s': t_start,
                   'pool_per_s_steady': n / max(t_pool - t_start, 1e-9)}
            if dask:
                t_dask, _ = timed(job, batch, engine='dask', workers=workers)
                row['dask_per_s_with_startup'] = n / t_dask
            out['rows'].append(row)
    return out


def table(results: dict) -> str:
    """Markdown: one row per backend and metrics."""
    dask = any('dask_per_s_with_startup' in r for r in results['rows'])
    w = results['workers']
    lines = ['| backend | metrics | candidates | optimal / infeasible | serial /s | '
             f'pool of {w} /s, steady | with start-up (start-up s) |'
             + (' local Dask cluster /s, with start-up |' if dask else ''),
             '|---|---|---:|---|---:|---:|---|' + ('---:|' if dask else '')]
    for r in results['rows']:
        lines.append(f"| {r['backend']} | {r['metrics']} | {r['candidates']} | "
                     f"{r['optimal']} / {r['infeasible']} | {r['serial_per_s']:.0f} | "
                     f"{r['pool_per_s_steady']:.0f} | {r['pool_per_s_with_startup']:.0f} "
                     f"({r['pool_startup_s']:.2f}) |"
                     + (f" {r['dask_per_s_with_startup']:.0f} |" if dask else ''))
    t = results['targets']
    lines.append(f"\ntargets on 2 cores: basic >= {t['basic']:.0f}/s with the fastest backend, "
                 f"full >= {t['full']:.0f}/s")
    return '\n'.join(lines)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument('--count', type=int, default=4000, help='candidates (full metrics: half)')
    p.add_argument('--seed', type=int, default=0)
    p.add_argument('--workers', type=int, default=2)
    p.add_argument('--backends', nargs='+', default=['daqp', 'proxsuite'])
    p.add_argument('--dask', action='store_true', help='also a local Dask cluster')
    p.add_argument('--out', type=Path, help='write the results as JSON here')
    a = p.parse_args()
    res = run(a.count, a.seed, a.workers, tuple(a.backends), a.dask)
    report(res, table(res), a.out, f'{a.count} candidates, seed {a.seed}; threads: '
           f"{res['blas_threads']}")
    return 0


if __name__ == '__main__':
    sys.exit(main())
