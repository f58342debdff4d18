# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
How long one control cycle can take at the edges of the node's parameter ranges.

Usage: .venv/bin/python bench/bounds.py [--grasps 40] [--out FILE]

For the bundled scenarios and an Allegro grasp with MAX_CONTACTS contacts (the largest a
scenario may hold), each cycle is run with the solver settings at their bounds
(``solver.max_iter`` 10000, ``solver.max_iter_in`` 200, ``solver.eps_abs`` 1e-12), the
weights' ratio at its bound (1e6, in three patterns), loads from 1 to 20 times the
scenario's (most of them unholdable) and the fallback on, under two budgets: the default
``cycle_budget`` (0.05 s) and its upper bound (1 s, with joint_state_timeout 1 s). It
reports the longest cycle and the longest overrun of the budget (the solvers keep it; one
ProxSuite outer iteration is what they can overrun it by), and, for comparison, the
longest solve without a budget (iteration caps alone, on the first configuration of
each grasp, waited for at most UNBUDGETED_CAP_S). Speed is measured here, never
asserted in a test.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path
import time

from cycle import machine, report
from grasp_torque_opt.backends import make_solver, single_threaded_math
from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings
from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.parameters.generated import CycleConfig
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.scenario import MAX_CONTACTS
from grasp_torque_opt.core.scenario_fields import ContactSpec
from grasp_torque_opt.core.tau_qp import build_tau_qp
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
BOUNDS = ProxSuiteSettings(eps_abs=1e-12, max_iter=10000, max_iter_in=200)
LOADS = (1.0, 2.0, 5.0, 10.0, 20.0)
BUDGETS = (0.05, 1.0)
#: Longest solve without a budget that is waited for [s].
UNBUDGETED_CAP_S = 20.0


def weight_patterns(m: int) -> dict[str, np.ndarray]:
    """W at the node's bound: the largest entry 1e6 times the smallest."""
    return {'alternating': np.array([1e-3, 1e3] * (m // 2) + [1.0] * (m % 2)),
            'one small': np.r_[1e-3, np.full(m - 1, 1e3)],
            'one large': np.r_[1e3, np.full(m - 1, 1e-3)]}


def many_contacts(setup: GraspSetup, p: int) -> GraspSetup:
    """Return the grasp with p contacts: each fingertip's, repeated at points spread on its pad."""
    rng = np.random.default_rng(0)
    contacts = []
    for k in range(p):
        c = setup.contacts[k % len(setup.contacts)]
        contacts.append(ContactSpec(link=c.link, position=c.position + rng.normal(0, 2e-3, 3),
                                    normal=c.normal, tangent=c.tangent))
    return dataclasses.replace(setup, contacts=contacts)


def grasps(n: int) -> list[tuple[str, GraspSetup]]:
    out = []
    for name in ('planar_two_finger.yaml', 'allegro_right.yaml'):
        out.append((name, GraspSetup.from_file(ROOT / 'config' / name)))
    out.append((f'allegro, {MAX_CONTACTS} contacts', many_contacts(out[1][1], MAX_CONTACTS)))
    rng = np.random.default_rng(1)
    cases = []
    for label, setup in out:
        for _ in range(n):
            q = setup.q.copy()
            q[setup.hand.idx_q] += rng.uniform(-0.02, 0.02, setup.hand.m)
            cases.append((label, dataclasses.replace(setup, q=q)))
    return cases


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--grasps', type=int, default=40, help='configurations per scenario')
    parser.add_argument('--out', type=Path,
                        default=Path(__file__).resolve().parent / 'results' / 'bounds.json')
    args = parser.parse_args()
    single_threaded_math()
    rows = {}
    for label, setup in grasps(args.grasps):
        m = setup.hand.m
        row = rows.setdefault(label, {'cycles': 0, 'unholdable': 0, 'commands': 0,
                                      'unbudgeted_max_s': 0.0,
                                      **{f'max_cycle_s@{b}': 0.0 for b in BUDGETS},
                                      **{f'max_overrun_s@{b}': 0.0 for b in BUDGETS}})
        for load in LOADS:
            print(f'{label}, load x{load:g} ...', flush=True)
            for weights in weight_patterns(m).values():
                s = dataclasses.replace(setup, weights=weights,
                                        external_wrench=setup.external_wrench * load)
                maps = s.maps()
                qp = build_tau_qp(maps, s.friction, s.external_wrench, *s.tau_bounds, weights)
                if row['cycles'] < 2 * len(LOADS) * 3:  # the first configuration only
                    # Without a budget, up to max_iter x max_iter_in inner iterations: cut at
                    # UNBUDGETED_CAP_S, reported as reached.
                    t0 = time.perf_counter()
                    make_solver('proxsuite', BOUNDS).solve(qp, deadline=t0 + UNBUDGETED_CAP_S)
                    row['unbudgeted_max_s'] = max(row['unbudgeted_max_s'],
                                                  time.perf_counter() - t0)
                for budget in BUDGETS:
                    ctrl = TorqueController(
                        dataclasses.replace(s, hand=dataclasses.replace(s.hand)),
                        CycleConfig(cycle_budget=budget, joint_state_timeout=1.0),
                        BOUNDS, 'proxsuite', True, 'daqp')
                    names = list(s.hand.joints)
                    ctrl.take('joint_states',
                              JointStateReading(names, [float(s.q[i]) for i in s.hand.idx_q]), 0.0)
                    r = ctrl.cycle(0.0)
                    row['cycles'] += 1
                    row['commands'] += r.kind == 'solution'
                    row['unholdable'] += r.solution is not None and \
                        r.solution.status == 'infeasible'
                    row[f'max_cycle_s@{budget}'] = max(row[f'max_cycle_s@{budget}'], r.cycle_time)
                    row[f'max_overrun_s@{budget}'] = max(row[f'max_overrun_s@{budget}'],
                                                         r.cycle_time - budget)
    lines = ['| grasp | cycles | commands | unholdable | longest solve, no budget [ms] | '
             + ' | '.join(f'longest cycle, budget {b:g} s [ms] | longest overrun [ms]'
                          for b in BUDGETS) + ' |',
             '|---|---|---|---|---|' + '---|---|' * len(BUDGETS)]
    for label, r in rows.items():
        unbudgeted = (f"{1e3 * r['unbudgeted_max_s']:.1f}" if r['unbudgeted_max_s'] <
                      UNBUDGETED_CAP_S else f'over {UNBUDGETED_CAP_S:g} s')
        budgeted = ' | '.join(f"{1e3 * r[f'max_cycle_s@{b}']:.1f} | "
                              f"{1e3 * max(0.0, r[f'max_overrun_s@{b}']):.1f}" for b in BUDGETS)
        lines.append(f"| {label} | {r['cycles']} | {r['commands']} | {r['unholdable']} | "
                     f'{unbudgeted} | {budgeted} |')
    report({'machine': machine(), 'rows': rows, 'settings': dataclasses.asdict(BOUNDS)},
           '\n'.join(lines), args.out, "solver settings at the node's bounds")
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
