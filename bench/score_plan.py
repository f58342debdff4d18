# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Plan -> score: the planner's own lines scored on one core, beside raw DAQP in the same run.

Usage: .venv/bin/python bench/score_plan.py [--plan 300] [--times 20] [--seed 0]
       [--repeats 3] [--out bench/results/score_plan.json]

``plan_grasps`` (what ``grasp-torque-opt plan allegro_right.yaml --count 300 --seed 0``
writes: each line with its ``object``, ``grasp.object_origin`` and
``grasp.contact_tolerance``) gives ``--plan`` lines; they are scored ``--times`` over
(6,000 lines by default, numbered 1, 2, ...) in this process by the engine ``serial``
(one worker, as ``score --workers 1`` scores a chunk), its scorer bound before the clock
(start-up excluded), with basic and with full metrics. Beside each, in the same run:

- raw DAQP, basic: the same tau-QPs (built by the batch stages) solved by ``daqp.solve``
  cold, one Python call each (the faster of cold and a ``daqp.Model`` updated warm);
- raw DAQP, full: that QP and the candidate's 14 capacity LPs (the zero-load LP, its
  load and the 12 axes; :class:`~grasp_torque_opt.methods.capacity.CapacityLP`'s rows)
  by ``daqp.solve`` as :func:`grasp_torque_opt.methods.lp.solve_lp` calls it;
- how many lines the batch stages took and how many the single path scored (all of
  plan's lines should take the stages);
- the single path alone (``Scorer.score_lines``, as every plan line was scored before
  issue 36) on the ``--plan`` distinct lines, for the ratio.

Each figure is the median of ``--repeats`` runs, each raw run right after a scored run.
Rates depend on the machine's load: time on a quiet machine.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
import statistics
import sys
import time

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cycle import machine, report  # noqa: E402
from grasp_torque_opt.backends import single_threaded_math  # noqa: E402
from grasp_torque_opt.methods import engines  # noqa: E402
from grasp_torque_opt.methods.capacity import CapacityLP, DIRECTIONS  # noqa: E402
from grasp_torque_opt.methods.lp import EPS_PROX, MAX_ITER, PRIMAL_TOL  # noqa: E402
from grasp_torque_opt.methods.plan import plan_grasps, PlanSettings  # noqa: E402
from grasp_torque_opt.methods.score import ScoreJob, Scorer  # noqa: E402
from grasps import SCENARIO  # noqa: E402
import numpy as np  # noqa: E402


def tau_qps(batch, lines) -> list[tuple]:
    """Return the lines' tau-QPs as the batch stages build them: (H, A, bu, bl, sense)."""
    groups: dict[tuple, list] = {}
    for n, text in lines:
        item = batch.parse(n, text)
        groups.setdefault(item[2][1], []).append(item)
    out = []
    for parsed in groups.values():
        Q, W, C = batch.inputs(parsed)
        arrays = [np.array([item[2][j] for item in parsed]) for j in range(2, 7)]
        oMf, J6 = batch.kinematics.frames(Q, parsed[0][2][0])
        b = batch.cycle.build_batch(oMf, J6, *arrays, C, W)
        m = batch.H.shape[0]
        sense = np.zeros(b['bupper'].shape[1], dtype=np.int32)
        sense[m:m + b['n_eq']] = 5
        out.extend((batch.H, b['A'][i], b['bupper'][i], b['blower'][i], sense)
                   for i in np.flatnonzero(b['ok']))
    return out


def capacity_lps(job: ScoreJob, lines) -> list[tuple]:
    """Return each line's 14 capacity LPs as the single path has them (H, c, A, bu, bl, sense)."""
    scorer, out = Scorer(job), []
    for n, text in lines:
        _, setup = scorer.candidate(n, text)
        lp = CapacityLP(setup, setup.maps())
        load = setup.external_wrench
        loads = [load / np.abs(load).max()]
        for i, sign in DIRECTIONS.values():
            d = np.zeros(6)
            d[i] = sign
            loads.append(d)
        zero = lp.zero_form
        out.append((zero.H, lp.c, lp.A.copy(), zero.bu, zero.bl, zero.sense))
        for d in loads:
            A = lp.A.copy()
            A[:6, -1] = d
            out.append((lp.form.H, lp.c, A, lp.form.bu, lp.form.bl, lp.form.sense))
    return out


def raw_rate(qps: list[tuple], lps: list[tuple], candidates: int) -> float:
    """Candidates/s of DAQP alone on these QPs and LPs (one ``daqp.solve`` each)."""
    import daqp

    f = np.zeros(qps[0][0].shape[0])
    t0 = time.perf_counter()
    for H, A, bu, bl, sense in qps:
        daqp.solve(H, f, A, bu, bl, sense)
    for H, c, A, bu, bl, sense in lps:
        daqp.solve(H, c, A, bu, bl, sense, primal_tol=PRIMAL_TOL, iter_limit=MAX_ITER,
                   eps_prox=EPS_PROX)
    return candidates / (time.perf_counter() - t0)


def run(plan: int = 300, times: int = 20, seed: int = 0, repeats: int = 3) -> dict:
    """Plan's lines per second, basic and full, beside raw DAQP (JSON-able)."""
    single_threaded_math()
    found = plan_grasps(SCENARIO, PlanSettings(count=plan, seed=seed))
    lines = list(enumerate(found.lines() * times, 1))
    out = {'machine': machine(), 'planned': len(found.candidates), 'times': times,
           'lines': len(lines), 'seed': seed, 'repeats': repeats, 'rows': []}
    for metrics in ('basic', 'full'):
        job = ScoreJob.from_file(SCENARIO, metrics=metrics)
        engines.score_batch(job, lines[:2], engine='serial')  # binds the hand: not timed
        batch = engines.batch_scorer(job)
        staged, single = batch.staged, batch.single
        qps = tau_qps(batch, lines[:len(found.candidates)])
        lps = capacity_lps(job, lines[:len(found.candidates)]) if metrics == 'full' else []
        single_path = Scorer(job)
        distinct = lines[:len(found.candidates)]
        rates, raws, singles, records = [], [], [], []
        for _ in range(repeats):
            t0 = time.perf_counter()
            records = engines.score_batch(job, lines, engine='serial')
            rates.append(len(lines) / (time.perf_counter() - t0))
            raws.append(raw_rate(qps, lps, len(qps)))
            t0 = time.perf_counter()
            single_path.score_lines(distinct)
            singles.append(len(distinct) / (time.perf_counter() - t0))
        row = {'metrics': metrics, 'lines': len(lines),
               'optimal': sum(r['status'] == 'optimal' for r in records),
               'batch_stages': (batch.staged - staged) // repeats,
               'single_path': (batch.single - single) // repeats,
               'per_s': statistics.median(rates), 'raw_daqp_per_s': statistics.median(raws),
               'single_path_per_s': statistics.median(singles),
               'share_of_raw': statistics.median(r / w for r, w in zip(rates, raws))}
        out['rows'].append(row)
    return out


def table(results: dict) -> str:
    """Markdown: one row per metrics."""
    lines = ['| metrics | lines | optimal | batch stages / single path | plan lines /s, '
             'one worker | raw DAQP /s, same run | share of raw | single path alone /s |',
             '|---|---:|---:|---|---:|---:|---:|---:|']
    for r in results['rows']:
        lines.append(f"| {r['metrics']} | {r['lines']} | {r['optimal']} | "
                     f"{r['batch_stages']} / {r['single_path']} | {r['per_s']:.0f} | "
                     f"{r['raw_daqp_per_s']:.0f} | {100 * r['share_of_raw']:.1f}% | "
                     f"{r['single_path_per_s']:.0f} |")
    lines.append(f"\n{results['planned']} planned x {results['times']}, seed "
                 f"{results['seed']}; medians of {results['repeats']} runs")
    return '\n'.join(lines)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    p.add_argument('--plan', type=int, default=300, help='candidates planned')
    p.add_argument('--times', type=int, default=20, help='times each is scored')
    p.add_argument('--seed', type=int, default=0)
    p.add_argument('--repeats', type=int, default=3, help='runs per figure (the median)')
    p.add_argument('--out', type=Path, help='write the results as JSON here')
    a = p.parse_args()
    res = run(a.plan, a.times, a.seed, a.repeats)
    report(res, table(res), a.out, json.dumps({'plan': a.plan, 'times': a.times}))
    return 0


if __name__ == '__main__':
    sys.exit(main())
