# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
A fixed, seeded set of random feasible Allegro grasps for the benchmarks.

Usage: .venv/bin/python bench/grasps.py [--grasps 200] [--seed 0] [--out bench/results/grasps.json]

Distribution (:func:`allegro_grasps`): start from config/allegro_right.yaml
(16 joints, 4 fingertip contacts, ball of radius 0.04 m, N = 8, mu1 0.5,
mu2 0.005 m, f_min 0.5 N, |tau_i| <= 0.7 N m). Per candidate, drawn in this
order from one ``numpy.random.default_rng(seed)``:

- the 16 commanded joint positions, each moved by uniform noise in
  [-0.08, 0.08] rad and clipped to the URDF joint limits; the contact points
  stay fixed in their fingertip frames and the normals point from the contact
  point to the (unmoved) object origin, as the scenario says;
- the load, as bench/methods.py draws it: a force of uniformly random
  direction and 0.3 to 2 times the scenario's magnitude (1.47 N, the ball's
  weight), plus a random moment (normal, sigma 0.05 * 0.05 * magnitude N m).

A candidate is kept only if G and J are computable and the HiGHS LP
(:func:`grasp_torque_opt.reference.feasibility.linearized_feasible`) proves the
linearized problem (N = 8 polygon, torque limits) feasible; rejected
candidates still consume their draws, so the set depends only on (count, seed)
and the first k grasps of a larger set are the set of k. Run as a script, it
prints how many candidates were drawn and the spread of the kept ones.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
from pathlib import Path
import sys

import numpy as np

# The imports below need bench/ on sys.path for its sibling modules, so they follow
# code (E402) and stay out of the alphabetical block above (I100).
sys.path.insert(0, str(Path(__file__).resolve().parent))
from cycle import machine, report, ROOT  # noqa: E402, I100
from grasp_torque_opt.core.exceptions import GraspTorqueError  # noqa: E402
from grasp_torque_opt.core.grasp_setup import GraspSetup  # noqa: E402
from grasp_torque_opt.methods.engines import THREAD_VARS  # noqa: E402
from grasp_torque_opt.reference.feasibility import linearized_feasible  # noqa: E402

SCENARIO = ROOT / 'config' / 'allegro_right.yaml'
#: Half-width of the uniform joint-position noise [rad].
Q_NOISE = 0.08
#: Cap on candidates per kept grasp, so a bad seed cannot loop forever.
MAX_DRAWS_PER_GRASP = 50


def blas_threads() -> dict:
    """
    Return the thread settings this process runs with (None: the library's default, all cores).

    Multi-threaded OpenBLAS on the tiny matrices here can cost milliseconds per
    call on a busy machine, so every benchmark records them.
    """
    return {k: os.environ.get(k) for k in THREAD_VARS}


def draw_candidates(base: GraspSetup, seed: int):
    """Yield (q, w_ext) candidates forever from the distribution of the module docstring."""
    rng = np.random.default_rng(seed)
    hand = base.hand
    lo = np.asarray(hand.model.lowerPositionLimit)[hand.idx_q]
    hi = np.asarray(hand.model.upperPositionLimit)[hand.idx_q]
    scale = max(np.linalg.norm(base.external_wrench[:3]), 0.5)
    while True:
        q = base.q.copy()
        q[hand.idx_q] = np.clip(q[hand.idx_q] + rng.uniform(-Q_NOISE, Q_NOISE, hand.m), lo, hi)
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        force = d * scale * rng.uniform(0.3, 2.0)
        moment = rng.normal(size=3) * 0.05 * scale * 0.05
        yield q, np.concatenate((force, moment))


def allegro_grasps_with_stats(count: int = 200, seed: int = 0,
                              base: GraspSetup | None = None) -> tuple[list[GraspSetup], dict]:
    """Return the grasp set and how it was drawn (candidates drawn, rejected and why)."""
    base = base or GraspSetup.from_file(SCENARIO)
    tau_min, tau_max = base.tau_bounds
    kept: list[GraspSetup] = []
    rejected = {'maps': 0, 'infeasible': 0, 'lp_undecided': 0}
    drawn = 0
    for q, w in draw_candidates(base, seed):
        if len(kept) == count:
            break
        if drawn >= MAX_DRAWS_PER_GRASP * max(count, 1):
            raise RuntimeError(f'only {len(kept)} feasible grasps in {drawn} candidates')
        drawn += 1
        setup = dataclasses.replace(base, q=q, external_wrench=w)
        try:
            maps = setup.maps()
        except GraspTorqueError:
            rejected['maps'] += 1
            continue
        if not (np.all(np.isfinite(maps.G)) and np.all(np.isfinite(maps.J))):
            rejected['maps'] += 1
            continue
        feasible = linearized_feasible(maps, setup.friction, w, tau_min, tau_max)
        if feasible is None:
            rejected['lp_undecided'] += 1
        elif not feasible:
            rejected['infeasible'] += 1
        else:
            kept.append(setup)
    return kept, {'count': count, 'seed': seed, 'drawn': drawn, 'rejected': rejected}


def allegro_grasps(count: int = 200, seed: int = 0,
                   base: GraspSetup | None = None) -> list[GraspSetup]:
    """
    ``count`` feasible Allegro grasps, deterministic in (count, seed); see the module docstring.

    Args:
        count: number of grasps kept.
        seed: seed of the one generator every draw comes from.
        base: the setup to perturb (default: config/allegro_right.yaml, loaded here).
    """
    return allegro_grasps_with_stats(count, seed, base)[0]


def run(count: int = 200, seed: int = 0) -> dict:
    """Draw the set and describe it (JSON-able)."""
    base = GraspSetup.from_file(SCENARIO)
    grasps, stats = allegro_grasps_with_stats(count, seed, base)
    dq = np.array([g.q[base.hand.idx_q] - base.q[base.hand.idx_q] for g in grasps])
    force = np.array([np.linalg.norm(g.external_wrench[:3]) for g in grasps])
    moment = np.array([np.linalg.norm(g.external_wrench[3:]) for g in grasps])
    return {'machine': machine(), 'blas_threads': blas_threads(), **stats,
            'dq_abs_max_rad': float(np.abs(dq).max()),
            'dq_abs_median_rad': float(np.median(np.abs(dq))),
            'force_N': {'min': float(force.min()), 'median': float(np.median(force)),
                        'max': float(force.max())},
            'moment_Nm': {'min': float(moment.min()), 'median': float(np.median(moment)),
                          'max': float(moment.max())}}


def table(results: dict) -> str:
    """Format a short markdown table of the set's make-up."""
    r = results
    rej = r['rejected']
    return '\n'.join([
        '| grasps | seed | drawn | rejected: infeasible | LP undecided | maps | '
        'max abs dq [rad] | force [N] min / median / max |',
        '|---:|---:|---:|---:|---:|---:|---:|---|',
        f"| {r['count']} | {r['seed']} | {r['drawn']} | {rej['infeasible']} | "
        f"{rej['lp_undecided']} | {rej['maps']} | {r['dq_abs_max_rad']:.3f} | "
        f"{r['force_N']['min']:.2f} / {r['force_N']['median']:.2f} / {r['force_N']['max']:.2f} |",
    ])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--grasps', type=int, default=200)
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--out', type=Path, help='write the results as JSON here')
    args = parser.parse_args()
    res = run(args.grasps, args.seed)
    report(res, table(res), args.out,
           f"threads: {res['blas_threads']}")


if __name__ == '__main__':
    main()
