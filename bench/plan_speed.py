# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Planning speed from outside: ``grasp-torque-opt plan`` as a separate process, one core.

Usage: .venv/bin/python bench/plan_speed.py [--allegro 200] [--g1 50] [--seed 0]
       [--repeats 3] [--baseline-ref 2ef7ef1] [--out bench/results/plan_speed.json]

Each run is the command a user types, ``grasp-torque-opt plan config/allegro_right.yaml
--count N --seed S --out FILE`` (the bundled Allegro and its ball, fingertip spheres)
and the same on ``config/g1_right.yaml`` (the G1's Dex3-1 hand, its collision meshes,
in the whole robot's URDF), in a child process with its BLAS/OpenMP threads at 1 (one
core), timed by its wall clock from start to exit. Start-up is the same command with
``--count 1`` (Python, imports, the URDF and meshes, the first candidate); the rate
without start-up is (N - 1) / (time at N - time at 1). From the summary line the
planner prints on stderr: the candidates found, the IKs run, the refusals by reason.

The baseline, in the same run: the planner at ``--baseline-ref`` (default 2ef7ef1, the
commit before issue 36's planner changes): its ``grasp_torque_opt`` exported by ``git
archive`` into a temporary folder (the compiled extension copied in), run by this venv's
Python on the same config files (``PYTHONPATH`` puts it before the installed package).
``--baseline-ref none`` skips it.

Each figure is the median of ``--repeats`` runs, the variants interleaved. Rates depend
on the machine's load: time on a quiet machine. Targets (issue 36): at least 100
Allegro sphere candidates/s and 10 G1 mesh candidates/s per core.
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cycle import machine, report  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
HANDS = {'allegro': ('config/allegro_right.yaml', 100.0), 'g1': ('config/g1_right.yaml', 10.0)}
SUMMARY = re.compile(r'planned (\d+) of (\d+) candidates in (\d+) IKs \(seed \d+; '
                     r'rejected: (.*)\)')
ONE_CORE = {'OMP_NUM_THREADS': '1', 'OPENBLAS_NUM_THREADS': '1', 'MKL_NUM_THREADS': '1'}


def export(ref: str, into: Path) -> Path:
    """Export ``grasp_torque_opt`` at ``ref`` into ``into``, the built extension copied in."""
    archive = subprocess.run(['git', '-C', str(ROOT), 'archive', ref, 'grasp_torque_opt'],
                             check=True, capture_output=True).stdout
    subprocess.run(['tar', '-x', '-C', str(into)], input=archive, check=True)
    for built in (ROOT / 'grasp_torque_opt' / 'native').glob('*.so'):
        shutil.copy(built, into / 'grasp_torque_opt' / 'native' / built.name)
    return into


def command(variant: str | Path, hand: str, count: int, seed: int, out: Path) -> tuple:
    """Return (argv, env) of one plan run: the installed command, or the exported tree."""
    env = {**os.environ, **ONE_CORE}
    args = ['plan', str(ROOT / HANDS[hand][0]), '--count', str(count), '--seed', str(seed),
            '--out', str(out)]
    if variant == 'current':
        exe = Path(sys.executable).parent / 'grasp-torque-opt'
        return [str(exe), *args], env
    env['PYTHONPATH'] = str(variant)  # the exported package before the installed one
    code = 'import sys; from grasp_torque_opt.cli import main; sys.exit(main())'
    return [sys.executable, '-c', code, *args], env


def run_once(variant, hand: str, count: int, seed: int) -> dict:
    """Run the planner once; return its wall time and what its summary line says."""
    with tempfile.TemporaryDirectory() as tmp:
        argv, env = command(variant, hand, count, seed, Path(tmp) / 'plan.jsonl')
        start = time.perf_counter()
        done = subprocess.run(argv, env=env, capture_output=True, text=True, cwd=tmp)
        wall = time.perf_counter() - start
    match = SUMMARY.search(done.stderr)
    if match is None:
        raise RuntimeError(f'{hand} {variant}: no summary line (exit {done.returncode}): '
                           f'{done.stderr[-400:]}')
    rejected = {}
    if match.group(4) != 'none':
        for part in match.group(4).split(', '):
            n, why = part.split(' ', 1)
            rejected[why] = int(n)
    return {'wall_s': wall, 'found': int(match.group(1)), 'iks': int(match.group(3)),
            'rejected': rejected}


def run(counts: dict, seed: int, repeats: int, variants: dict) -> dict:
    """Time every hand and variant, interleaved; return the medians."""
    rows = []
    for hand, count in counts.items():
        runs = {name: {'full': [], 'startup': []} for name in variants}
        for _ in range(repeats):
            for name, variant in variants.items():
                runs[name]['startup'].append(run_once(variant, hand, 1, seed))
                runs[name]['full'].append(run_once(variant, hand, count, seed))
        for name in variants:
            full, startup = runs[name]['full'], runs[name]['startup']
            wall = statistics.median(r['wall_s'] for r in full)
            first = statistics.median(r['wall_s'] for r in startup)
            last = full[-1]
            rows.append({'hand': hand, 'variant': name, 'count': count,
                         'found': last['found'], 'iks': last['iks'],
                         'iks_per_kept': last['iks'] / max(last['found'], 1),
                         'rejected': last['rejected'], 'wall_s': wall, 'startup_s': first,
                         'per_s_with_startup': last['found'] / wall,
                         'per_s': (last['found'] - 1) / max(wall - first, 1e-9),
                         'target_per_s': HANDS[hand][1],
                         'walls_s': [r['wall_s'] for r in full],
                         'startups_s': [r['wall_s'] for r in startup]})
    return {'machine': machine(), 'seed': seed, 'repeats': repeats, 'rows': rows}


def table(results: dict) -> str:
    """Markdown: one row per hand and variant, the current one's speed-up beside it."""
    lines = ['| hand | planner | found / asked | IKs (per kept) | rejected | time s | '
             'start-up s | /s with start-up | /s without | target /s | speed-up |',
             '|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|']
    base = {r['hand']: r for r in results['rows'] if r['variant'] != 'current'}
    for r in results['rows']:
        why = ', '.join(f'{n} {k}' for k, n in sorted(r['rejected'].items())) or 'none'
        ref = base.get(r['hand'])
        speed = (f"{r['per_s'] / ref['per_s']:.1f}x" if ref and r is not ref else '')
        lines.append(f"| {r['hand']} | {r['variant']} | {r['found']} / {r['count']} | "
                     f"{r['iks']} ({r['iks_per_kept']:.2f}) | {why} | {r['wall_s']:.2f} | "
                     f"{r['startup_s']:.2f} | {r['per_s_with_startup']:.1f} | "
                     f"{r['per_s']:.1f} | {r['target_per_s']:.0f} | {speed} |")
    lines.append(f"\nseed {results['seed']}; medians of {results['repeats']} runs; one "
                 'core (BLAS/OpenMP threads 1); /s without start-up = (found - 1) / (time '
                 '- time of --count 1)')
    return '\n'.join(lines)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    p.add_argument('--allegro', type=int, default=200, help='Allegro sphere candidates')
    p.add_argument('--g1', type=int, default=50, help='G1 candidates (its meshes)')
    p.add_argument('--seed', type=int, default=0)
    p.add_argument('--repeats', type=int, default=3, help='runs per figure (the median)')
    p.add_argument('--baseline-ref', default='2ef7ef1',
                   help="the planner's git ref to compare with ('none': no baseline)")
    p.add_argument('--out', type=Path, help='write the results as JSON here')
    a = p.parse_args()
    counts = {k: v for k, v in (('allegro', a.allegro), ('g1', a.g1)) if v > 0}
    with tempfile.TemporaryDirectory() as tmp:
        variants: dict = {}
        if a.baseline_ref != 'none':
            variants[a.baseline_ref] = export(a.baseline_ref, Path(tmp))
        variants['current'] = 'current'
        res = run(counts, a.seed, a.repeats, variants)
    res['baseline_ref'] = a.baseline_ref
    report(res, table(res), a.out, json.dumps({'allegro': a.allegro, 'g1': a.g1}))
    return 0


if __name__ == '__main__':
    sys.exit(main())
