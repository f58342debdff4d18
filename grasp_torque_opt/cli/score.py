# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""``grasp-torque-opt score CANDIDATES``: candidate grasps scored in parallel, ranked."""

from __future__ import annotations

import argparse
import shutil
import sys
import time

from grasp_torque_opt.backends import BACKENDS
from grasp_torque_opt.cli.args import count, PROG
from grasp_torque_opt.core.command_line import (
    EXIT_BAD_INPUT,
    EXIT_FAILED,
    EXIT_OK,
    HelpFormatter,
    one_line,
)
from grasp_torque_opt.core.resources import find_config
from grasp_torque_opt.core.scenario import OBJECTIVES
from grasp_torque_opt.methods.engines import ENGINES, read_candidates, score_batch
from grasp_torque_opt.methods.ranking import (
    format_table,
    rank,
    rank_key,
    RANK_KEYS,
    record_json,
    summary,
)
from grasp_torque_opt.methods.score import METRICS, ScoreJob


def add_parser(sub) -> None:
    """Add ``score`` to the CLI's subparsers."""
    p = sub.add_parser('score', help='score candidate grasps of one hand (JSON Lines), in '
                       'parallel, ranked', formatter_class=HelpFormatter,
                       description=(
                           'Score candidate grasps: each line of CANDIDATES is a JSON object, '
                           'a partial scenario merged into --scenario (docs/planner.md).'),
                       epilog='exit codes: 0 every line scored, 2 a bad line (each named on '
                       'stderr, the others scored) or a bad base scenario or candidates file, '
                       '4 any other error.')
    p.add_argument('candidates', help='JSON Lines file, one candidate per line')
    p.add_argument('--scenario', required=True, help='base scenario YAML file, or the name '
                   'of a bundled one (the hand and every default)')
    p.add_argument('--out', help='write one JSON record per candidate here (JSON Lines, '
                   'input order, with its rank)')
    p.add_argument('--json', action='store_true', help='print the records (JSON Lines, '
                   'ranked) instead of the table')
    p.add_argument('--top', type=count(0, 10**9), default=10,
                   help='rows of the ranked table')
    p.add_argument('--rank-by', choices=tuple(RANK_KEYS), default='capacity',
                   help='capacity (largest first; torque_norm with --metrics basic) or '
                        'torque_norm, max_torque_ratio, friction_usage_max (smallest first)')
    p.add_argument('--metrics', choices=METRICS, default='full',
                   help='full (with the capacities) or basic (solve only)')
    p.add_argument('--workers', type=count(1, 256), help='processes, 1 to 256 (default: the '
                   "machine's cores)")
    p.add_argument('--engine', choices=ENGINES, default='processes',
                   help='processes, serial, or dask (Dask distributed)')
    p.add_argument('--scheduler', help='Dask scheduler address (engine dask; default: a '
                   'local cluster)')
    p.add_argument('--backend', choices=BACKENDS, default='daqp',
                   help='QP backend (daqp: the fastest on these grasps)')
    p.add_argument('--objective', choices=OBJECTIVES, help='objective instead of the '
                   "scenario's")
    p.add_argument('--no-progress', action='store_true', help='no progress bar')
    p.add_argument('--solutions', action='store_true', help="also record each candidate's "
                   'torques (tau) and contact wrenches, so the winner need not be solved '
                   'again (larger records)')


class _Progress:
    """A progress bar on stderr (tqdm), drawn only on a terminal."""

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled and sys.stderr.isatty()
        self.bar = None

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled:
            return
        if self.bar is None:
            from tqdm import tqdm

            # A terminal without a size (a pty's 0 x 0) would get no bar at all:
            # shutil's size falls back to 80 x 24 there.
            cols, rows = shutil.get_terminal_size()
            self.bar = tqdm(total=total, desc='scoring', unit='candidate', file=sys.stderr,
                            ncols=cols, nrows=rows)
        self.bar.update(done - self.bar.n)
        if done >= total:
            self.bar.close()


def run(args: argparse.Namespace) -> int:
    """
    Score the candidates, print the ranked table (or the records), return the exit code.

    ``args.where`` follows what is being read (the base scenario, then the candidates),
    so that a bad input's line names its file.
    """
    args.where = args.scenario
    job = ScoreJob.from_file(find_config(args.scenario), backend=args.backend,
                             metrics=args.metrics, objective=args.objective,
                             solutions=args.solutions)
    args.where = args.candidates
    lines = read_candidates(args.candidates)
    args.where = args.scenario
    t0 = time.perf_counter()
    records = score_batch(job, lines, workers=args.workers, engine=args.engine,
                          scheduler=args.scheduler, progress=_Progress(not args.no_progress))
    seconds = time.perf_counter() - t0
    args.where = None
    by = rank_key(records, args.rank_by)
    ranked = rank(records, by)
    for i, r in enumerate(ranked, 1):
        r['rank'] = i
    bad = [r for r in records if r['status'] == 'error']
    for r in bad:
        print(one_line(f"{PROG}: error: {args.candidates}: {r['error']}"), file=sys.stderr)
    if args.out:
        try:
            with open(args.out, 'w') as fh:
                fh.writelines(record_json(r) + '\n' for r in records)
        except OSError as e:
            print(one_line(f'{PROG}: error: --out: cannot write {args.out}: {e.strerror}'),
                  file=sys.stderr)
            return EXIT_FAILED
    if args.json:
        for r in ranked:
            print(record_json(r))
    else:
        print(f'{args.candidates}: {len(records)} candidates on {args.scenario} '
              f'(ranked by {by})')
        print(format_table(ranked, args.top))
        print(summary(records, seconds))
    return EXIT_BAD_INPUT if bad else EXIT_OK
