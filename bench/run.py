# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The whole benchmark suite, one command: results as JSON and one markdown summary.

Usage (from a fresh clone):

    bash scripts/setup.sh && .venv/bin/python bench/run.py [--quick] [--skip-node]
         [--out bench/results]

Runs, in this order, each writing ``OUT/<name>.json``:

- ``cycle``: the full control cycle per backend, both hands (bench/cycle.py);
- ``solvers``: every solver side by side on the scenarios and on 200 seeded
  feasible Allegro grasps, ProxSuite tuning, warm starts (bench/solvers.py);
- ``linearization``: the polygon's torque excess over the exact cone for N = 3
  to 32 (bench/linearization.py);
- ``adaptive``: tau-qp-adaptive's excess, certified gap and time against the
  fixed polygons and the SOCP, planar case and 200 grasps (bench/adaptive.py);
- ``planner``: grasps scored per second, one process and both cores
  (bench/planner.py);
- ``score``: ``grasp-torque-opt score``'s candidates per second, basic and full
  metrics (capacities), serial and over both cores (bench/score.py);
- ``node_load``: the node at 500 Hz and 1 kHz beside a trivial echo node, in
  separate processes (bench/node_load.py; skipped with ``--skip-node``);
- ``node_blackbox``: the node on the default params file, measured from outside
  as a user would (joint states published, effort commands counted), beside the
  echo node and the old cold ProxSuite default (bench/node_blackbox.py; skipped
  with ``--skip-node``).

then ``OUT/summary.md``: the machine, the date and each part's table, which the
docs/benchmarks.md shows. ``--quick`` runs everything small (a smoke
test of the suite, not figures to quote). The soak run (bench/soak.py, 10
minutes) is separate. BLAS runs single-threaded, as in the node.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
import subprocess
import sys
import time

HERE = Path(__file__).resolve().parent
# The imports below need bench/ on sys.path for its sibling modules, so they follow
# code (E402).
sys.path.insert(0, str(HERE))

import adaptive  # noqa: E402
import cycle  # noqa: E402
from grasp_torque_opt.backends import single_threaded_math  # noqa: E402
import linearization  # noqa: E402
import node_blackbox  # noqa: E402
import node_load  # noqa: E402
import planner  # noqa: E402
import score  # noqa: E402
import solvers  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--out', type=Path, default=HERE / 'results')
    parser.add_argument('--quick', action='store_true', help='small sizes: a smoke test')
    parser.add_argument('--skip-node', action='store_true', help='skip the node under load')
    args = parser.parse_args()
    single_threaded_math()
    args.out.mkdir(parents=True, exist_ok=True)
    grasps = 20 if args.quick else 200
    parts = [
        ('cycle', lambda: cycle.run(repeats=200 if args.quick else 3000), cycle.table),
        ('solvers', lambda: solvers.run(grasps=grasps, repeats=3 if args.quick else 5,
                                        scenario_repeats=20 if args.quick else 200,
                                        steps=50 if args.quick else 500), solvers.table),
        ('linearization', lambda: linearization.run(grasps=grasps, backend='daqp'),
         linearization.table),
        ('adaptive', lambda: adaptive.run(grasps=grasps, repeats=3 if args.quick else 7,
                                          steps=50 if args.quick else 500),
         adaptive.table),
        ('planner', lambda: planner.run(grasps=grasps, rounds=1 if args.quick else 5),
         planner.table),
        ('score', lambda: score.run(count=400 if args.quick else 4000), score.table),
    ]
    machine = cycle.machine()
    summary = [f'# Benchmark summary\n\n{cycle.machine_line(machine)}\n']
    for name, run, table in parts:
        t0 = time.monotonic()
        print(f'== {name}', flush=True)
        results = run()
        (args.out / f'{name}.json').write_text(json.dumps(results, indent=2))
        text = table(results)
        print(text, flush=True)
        summary.append(f'## {name} ({time.monotonic() - t0:.0f} s)\n\n{text}\n')
    if not args.skip_node:
        for name, module, quick in (('node_load', node_load, ['--hands', 'allegro']),
                                    ('node_blackbox', node_blackbox, [])):
            print(f'== {name}', flush=True)
            path = args.out / f'{name}.json'
            cmd = [sys.executable, str(HERE / f'{name}.py'), '--out', str(path)]
            if args.quick:
                cmd += ['--duration', '2'] + quick
            t0 = time.monotonic()
            done = subprocess.run(cmd)
            table = module.table(json.loads(path.read_text())['cases']) if path.exists() \
                else f'{name} failed (exit {done.returncode}); see its output above'
            summary.append(f'## {name} ({time.monotonic() - t0:.0f} s)\n\n{table}\n')
    (args.out / 'summary.md').write_text('\n'.join(summary))
    print(f"written: {args.out}/*.json and {args.out / 'summary.md'}")
    return 0


if __name__ == '__main__':
    sys.exit(main())
