# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Write a batch of candidate Allegro grasps as JSON Lines, for ``grasp-torque-opt score``.

Usage: .venv/bin/python bench/candidates.py [--count 1000] [--seed 0] [--bad 0]
       [--out candidates.jsonl]

Each line is a scenario override of config/allegro_right.yaml (docs/planner.md):
the 16 joint positions moved by uniform noise in [-0.08, 0.08] rad and a load of
random direction and 0.3 to 2 times the ball's weight with a small random moment,
drawn as bench/grasps.py draws them (its ``draw_candidates``), but unfiltered: some
candidates are infeasible, as a planner's would be. ``"gravity": null`` makes the
line's ``load.external_wrench`` the whole load. ``--bad K`` replaces every K-th
line by a malformed one (an unknown link), to see the batch go on past it.
"""

from __future__ import annotations

import argparse
from itertools import islice
import json
from pathlib import Path
import sys

# The imports below need bench/ on sys.path for its sibling modules, so they follow
# code (E402).
sys.path.insert(0, str(Path(__file__).resolve().parent))
from grasp_torque_opt.core.grasp_setup import GraspSetup  # noqa: E402
from grasps import draw_candidates, SCENARIO  # noqa: E402


def candidate_lines(count: int = 1000, seed: int = 0, bad: int = 0) -> list[str]:
    """``count`` JSON lines (see the module docstring)."""
    base = GraspSetup.from_file(SCENARIO)
    hand = base.hand
    out = []
    for i, (q, w) in enumerate(islice(draw_candidates(base, seed), count)):
        line = {'id': f'c{i}', 'gravity': None,
                'grasp': {'joint_positions': {j: round(float(x), 6) for j, x in
                                              zip(hand.joints, q[hand.idx_q])}},
                'load': {'external_wrench': [round(float(x), 6) for x in w]}}
        if bad and i % bad == bad - 1:
            line['grasp']['contacts'] = [{'link': 'no_such_link'}]
        out.append(json.dumps(line))
    return out


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument('--count', type=int, default=1000)
    p.add_argument('--seed', type=int, default=0)
    p.add_argument('--bad', type=int, default=0, help='every K-th line malformed (0: none)')
    p.add_argument('--out', type=Path, help='file to write (default: stdout)')
    a = p.parse_args()
    text = '\n'.join(candidate_lines(a.count, a.seed, a.bad)) + '\n'
    if a.out:
        a.out.write_text(text)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == '__main__':
    sys.exit(main())
