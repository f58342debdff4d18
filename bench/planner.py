# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Planner throughput: Allegro grasps scored per second, one core and several.

Usage: .venv/bin/python bench/planner.py [--grasps 200] [--seed 0] [--rounds 5]
       [--workers 2] [--backends proxsuite daqp] [--out bench/results/planner.json]

A planner scores a batch of candidate grasps; here the batch is the seeded
Allegro grasp set of bench/grasps.py (each candidate a joint configuration and
a load), scored ``--rounds`` times over so that a run lasts long enough to
time. Scoring one candidate is the full solve(setup, solver=...) of the
project: kinematics (G, J), build, solve, certificate, and the HiGHS LP when a
solver says infeasible or fails; a candidate counts as certified when the
status is "optimal". Each process reuses one solver of the backend
(make_solver) across its candidates; only (q, w_ext) travel to the workers,
which load the hand themselves once.

- sequential: this process, one solver.
- pool: multiprocessing (spawn) with ``--workers`` processes, the batch cut
  into chunks of 25 candidates. The workers' BLAS/OpenMP thread pools are set
  to ``--worker-threads`` (default 1, as a process-parallel planner would:
  two workers with a multi-threaded OpenBLAS each oversubscribe two cores);
  "default" leaves them to the environment. The sequential run uses this
  process's environment (recorded in the output); run the script with
  OPENBLAS_NUM_THREADS=1 to compare like with like. "with start-up" is timed from creating the pool
  (workers start, import, load the URDF, score one warm-up candidate each) to
  the last result; "without" starts once every worker has scored its warm-up
  candidate.

The issue's target: >= 5,000 Allegro grasps per second on 2 cores.
"""

from __future__ import annotations

import argparse
import dataclasses
import multiprocessing as mp
from pathlib import Path
import sys
import time

import numpy as np

# The imports below need bench/ on sys.path for its sibling modules, so they follow
# code (E402) and stay out of the alphabetical block above (I100).
sys.path.insert(0, str(Path(__file__).resolve().parent))
from cycle import machine, report  # noqa: E402, I100
from grasp_torque_opt.backends import make_solver  # noqa: E402
from grasp_torque_opt.core.grasp_setup import GraspSetup  # noqa: E402
from grasp_torque_opt.methods.dispatch import solve  # noqa: E402
from grasp_torque_opt.methods.engines import thread_env  # noqa: E402
from grasps import allegro_grasps, blas_threads, SCENARIO  # noqa: E402

CHUNK = 25
TARGET = 5000.0

_worker: dict = {}


def _init(backend: str, barrier=None) -> None:
    """Per process: the hand and one solver, kept for every chunk."""
    _worker['barrier'] = barrier
    _worker['base'] = GraspSetup.from_file(SCENARIO)
    _worker['solver'] = make_solver(backend)


def _score(chunk: tuple[np.ndarray, np.ndarray]) -> tuple[int, int]:
    """(scored, certified) of a chunk of candidates (q rows, w_ext rows)."""
    base, solver = _worker['base'], _worker['solver']
    certified = 0
    for q, w in zip(*chunk):
        sol = solve(dataclasses.replace(base, q=q, external_wrench=w), solver=solver)
        certified += sol.optimal
    return len(chunk[0]), certified


def _warm_up(chunk: tuple[np.ndarray, np.ndarray]) -> int:
    """Score one candidate, then wait for the other workers (so each takes exactly one)."""
    _score((chunk[0][:1], chunk[1][:1]))
    _worker['barrier'].wait(timeout=60)
    return mp.current_process().pid


def chunks(qs: np.ndarray, ws: np.ndarray, rounds: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Return the batch, ``rounds`` times over, cut into chunks of :data:`CHUNK`."""
    out = []
    for _ in range(rounds):
        for i in range(0, len(qs), CHUNK):
            out.append((qs[i:i + CHUNK], ws[i:i + CHUNK]))
    return out


def sequential(backend: str, work: list) -> dict:
    _init(backend)
    _score(work[0])  # first solve allocates the solver
    t0 = time.perf_counter()
    res = [_score(c) for c in work]
    elapsed = time.perf_counter() - t0
    scored, certified = map(sum, zip(*res))
    return {'scored': scored, 'certified': certified, 'seconds': elapsed,
            'grasps_per_s': scored / elapsed}


def pooled(backend: str, work: list, workers: int, worker_threads: str = '1') -> dict:
    ctx = mp.get_context('spawn')
    barrier = ctx.Barrier(workers)
    t0 = time.perf_counter()
    with thread_env(None if worker_threads == 'default' else worker_threads):
        pool = ctx.Pool(workers, initializer=_init, initargs=(backend, barrier))
    with pool:
        warm_up = [work[i % len(work)] for i in range(workers)]  # one each, even if few
        pids = set(pool.map(_warm_up, warm_up, chunksize=1))
        t1 = time.perf_counter()
        res = pool.map(_score, work, chunksize=1)
        t2 = time.perf_counter()
    scored, certified = map(sum, zip(*res))
    # Start-up: the pool's creation, the workers' start (imports, URDF) and
    # one warm-up candidate each (about a millisecond).
    startup = t1 - t0
    return {'workers': workers, 'worker_threads': worker_threads,
            'workers_that_warmed_up': len(pids), 'scored': scored,
            'certified': certified, 'seconds': t2 - t1, 'startup_seconds': startup,
            'grasps_per_s': scored / (t2 - t1),
            'grasps_per_s_with_startup': scored / (t2 - t1 + startup)}


def run(grasps: int = 200, seed: int = 0, rounds: int = 5, workers: int = 2,
        backends: tuple[str, ...] = ('proxsuite', 'daqp'), worker_threads: str = '1') -> dict:
    """Throughput per backend, sequential and pooled (JSON-able)."""
    setups = allegro_grasps(grasps, seed)
    qs = np.array([s.q for s in setups])
    ws = np.array([s.external_wrench for s in setups])
    work = chunks(qs, ws, rounds)
    out = {'machine': machine(), 'blas_threads': blas_threads(), 'grasps': grasps,
           'seed': seed, 'rounds': rounds,
           'target_grasps_per_s': TARGET, 'backends': {}}
    for b in backends:
        out['backends'][b] = {'sequential': sequential(b, work),
                              'pool': pooled(b, work, workers, worker_threads)}
    return out


def table(results: dict) -> str:
    """Markdown table: one row per backend and mode."""
    lines = ['| backend | mode | scored | certified | grasps/s | '
             'grasps/s with start-up (start-up s) |', '|---|---|---:|---:|---:|---|']
    for b, r in results['backends'].items():
        s, p = r['sequential'], r['pool']
        lines.append(f"| {b} | sequential | {s['scored']} | {s['certified']} | "
                     f"{s['grasps_per_s']:.0f} | |")
        lines.append(f"| {b} | pool of {p['workers']} ({p['worker_threads']} thread) | "
                     f"{p['scored']} | {p['certified']} | "
                     f"{p['grasps_per_s']:.0f} | {p['grasps_per_s_with_startup']:.0f} "
                     f"({p['startup_seconds']:.2f}) |")
    lines.append(f"\ntarget: {results['target_grasps_per_s']:.0f} grasps/s on 2 cores")
    return '\n'.join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--grasps', type=int, default=200)
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--rounds', type=int, default=5, help='times the batch is scored')
    parser.add_argument('--workers', type=int, default=2)
    parser.add_argument('--backends', nargs='+', default=['proxsuite', 'daqp'])
    parser.add_argument('--worker-threads', default='1',
                        help="BLAS/OpenMP threads per pool worker, or 'default'")
    parser.add_argument('--out', type=Path, help='write the results as JSON here')
    args = parser.parse_args()
    res = run(args.grasps, args.seed, args.rounds, args.workers, tuple(args.backends),
              args.worker_threads)
    report(res, table(res), args.out,
           f'{args.grasps} grasps x {args.rounds} rounds, seed {args.seed}; '
           f"threads: {res['blas_threads']} (pool workers: {args.worker_threads})")


if __name__ == '__main__':
    main()
