# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""``grasp-torque-opt solve SCENARIO``: one scenario, one method, its certificate."""

from __future__ import annotations

import argparse

from grasp_torque_opt.backends import BACKENDS, make_solver
from grasp_torque_opt.cli.args import EPILOG, margin, overridden, SCENARIO_HELP
from grasp_torque_opt.core.command_line import EXIT_FAILED, EXIT_INFEASIBLE, EXIT_OK, \
    HelpFormatter
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.report import solution_dict, strict_json
from grasp_torque_opt.core.resources import find_config
from grasp_torque_opt.core.scenario import OBJECTIVES
from grasp_torque_opt.core.solution import INFEASIBLE, OPTIMAL
from grasp_torque_opt.methods.adaptive import AdaptiveSettings, Refiner
from grasp_torque_opt.methods.dispatch import LINEARIZED, METHODS, solve

#: The methods, in words (docs/method.md).
METHOD_HELP = ("tau-qp: the paper's QP over joint torques, the N-gon cones; "
               'tau-qp-adaptive: tau-qp refined towards the exact cone, with a certified '
               'gap; force-qp: the QP over contact forces; socp: the exact cone (Clarabel); '
               'nlp: the exact cone (SciPy)')


def add_parser(sub) -> None:
    """Add ``solve`` to the CLI's subparsers."""
    p = sub.add_parser('solve', help='solve one scenario with one method',
                       formatter_class=HelpFormatter, epilog=EPILOG, description=(
                           'Solve one scenario: the torques, their certificate, and '
                           'with --json one JSON object (docs/design.md section 4.2).'))
    p.add_argument('scenario', help=SCENARIO_HELP)
    p.add_argument('--method', choices=METHODS, default='tau-qp', help=METHOD_HELP)
    p.add_argument('--backend', choices=BACKENDS, default='proxsuite',
                   help='QP solver of the tau-qp method')
    p.add_argument('--fallback', choices=(*BACKENDS, 'none'), default='daqp',
                   help='backend asked when the first gives nothing certifiable')
    p.add_argument('--gap', type=_gap, default=AdaptiveSettings.gap_tolerance,
                   help='tau-qp-adaptive: stop at this certified gap to the exact optimum')
    p.add_argument('--max-rounds', type=_rounds, default=AdaptiveSettings.max_rounds,
                   help='tau-qp-adaptive: refinement rounds at most, 0 to 100')
    p.add_argument('--json', action='store_true', help='print one JSON object')
    p.add_argument('--objective', choices=OBJECTIVES,
                   help="objective instead of the scenario's objective.type")
    p.add_argument('--margin', type=margin, metavar='K',
                   help="friction margin k >= 0 instead of the scenario's friction.margin: "
                        'plan in the cone of mu/(1+k)')
    p.add_argument('--capacity', action='store_true',
                   help='also the load capacity and the 12 axis capacities')


def _gap(text: str) -> float:
    value = float(text)
    if not 0.0 < value < 1.0:  # False for NaN as well
        raise argparse.ArgumentTypeError(f'must be in (0, 1), got {text}')
    return value


def _rounds(text: str) -> int:
    value = int(text)
    if not 0 <= value <= 100:
        raise argparse.ArgumentTypeError(f'must be in [0, 100], got {text}')
    return value


def exit_code(status: str) -> int:
    """Return the exit code of a solution's status (docs/design.md section 4.2)."""
    return {OPTIMAL: EXIT_OK, INFEASIBLE: EXIT_INFEASIBLE}.get(status, EXIT_FAILED)


def run(args: argparse.Namespace) -> int:
    """Solve, print the answer (text or JSON) and return the exit code."""
    setup = overridden(GraspSetup.from_file(find_config(args.scenario)), args)
    fallback = None if args.fallback in ('none', args.backend) else make_solver(args.fallback)
    refiner = Refiner(AdaptiveSettings(gap_tolerance=args.gap, max_rounds=args.max_rounds))
    sol = solve(setup, args.method, backend=args.backend, fallback=fallback, refiner=refiner)
    maps = setup.maps()
    if sol.status == INFEASIBLE and args.method in LINEARIZED:
        from grasp_torque_opt.methods.explain import explain

        sol.infeasibility = explain(setup, maps).as_dict()
    d = solution_dict(sol, maps)
    if args.capacity:
        d['capacity'] = _capacity_dict(setup, maps)
    if args.json:
        print(strict_json(d))
    else:
        _print_solution(d)
    return exit_code(sol.status)


def _print_solution(d: dict) -> None:
    print(f"status: {d['status']} ({d['method']}; {d['message']})")
    if d.get('infeasibility'):
        print(f"why: {d['infeasibility']['text']}")
    if d['tau'] is not None:
        width = max(len(j) for j in d['joints'])
        for name, t in zip(d['joints'], d['tau']):
            print(f'  {name:<{width}}  {t:+.6f} N m')
        print(f"  ||tau||_2 = {d['torque_norm']:.6f} N m")
    print(f"solve time: {1e3 * d['solve_time_s']:.3f} ms, iterations: {d['iterations']}")
    if d['certificate'] is not None:
        c = d['certificate']
        print('certificate: ' + ', '.join(
            f'{k} {c[k]:.1e}' for k in ('equilibrium', 'torque', 'cone', 'normal_force',
                                        'torque_limit')) + f" (tolerance {c['tolerance']:.0e})")
    b = d.get('bounds')
    if b is not None:
        gap = '-' if b['gap'] is None else f"{100 * b['gap']:.3g}%"
        lower = 'none' if b['lower'] is None else f"{b['lower']:.6f}"
        print(f'bounds on the exact optimum of sqrt(tau^T W tau): lower {lower} N m, '
              f"this torque {b['upper']:.6f} N m, gap {gap} ({b['rounds']} rounds, "
              f"{b['qp_solves']} QPs, from {b['source']})" if b['upper'] is not None else
              f'bounds: lower {lower} N m, no certified torque')
    if d['tau'] is not None:
        usage = ' '.join(f"{100 * c['friction_usage']:.0f}%" for c in d['contacts'])
        print(f"objective: {d['objective']}, max |tau|/limit {d['max_torque_ratio']:.3f}, "
              f'friction usage per contact {usage} of the cone (margin '
              f"{d['friction_margin']:g})")
    if d.get('capacity'):
        cap = d['capacity']
        load = cap['load']
        print(f"capacity: {_cap(load['value'], 'times the load', load['status'])}; "
              f"holding it, {load['binding_text']}")
        print('axis capacities (largest load along each, alone): ' + ', '.join(
            f"{k} {_cap(v['value'], v['unit'], v['status'])}"
            for k, v in cap['directions'].items()))


def _cap(value, unit: str, status: str) -> str:
    return f'{value:.4g} {unit}' if value is not None else status


def _capacity_dict(setup: GraspSetup, maps) -> dict:
    """Build the solve --capacity JSON: ``load`` and ``directions`` (docs/planner.md)."""
    from grasp_torque_opt.methods.capacity import CapacityLP, direction_capacities

    lp = CapacityLP(setup, maps)
    load = lp.solve(setup.external_wrench)
    return {'load': {**load.as_dict(), 'binding_text': None if load.binding is None
                     else load.binding.text()},
            'directions': {k: c.as_dict() for k, c in
                           direction_capacities(setup, maps, lp).items()}}
