# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Command line: ``grasp-torque-opt solve|compare|plan SCENARIO``, ``... score CANDIDATES``.

Exit codes: 0 optimal, 3 infeasible, 2 bad input (one line on stderr naming
the field), 4 the solver gave nothing certifiable (no torque is printed).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
from pathlib import Path
import shutil
import sys
import time

from grasp_torque_opt.backends import BACKENDS, make_solver, single_threaded_math
from grasp_torque_opt.core.command_line import add_version, HelpFormatter
from grasp_torque_opt.core.exceptions import GraspTorqueError, InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.report import solution_dict, strict_json
from grasp_torque_opt.core.resources import find_config
from grasp_torque_opt.core.scenario import OBJECTIVES
from grasp_torque_opt.core.solution import INFEASIBLE, OPTIMAL
from grasp_torque_opt.methods.adaptive import AdaptiveSettings, Refiner
from grasp_torque_opt.methods.compare import compare, format_table
from grasp_torque_opt.methods.dispatch import LINEARIZED, METHODS, solve

EXIT_OPTIMAL, EXIT_BAD_INPUT, EXIT_INFEASIBLE, EXIT_FAILED = 0, 2, 3, 4
PROG = 'grasp-torque-opt'
#: Longest error line [characters].
MAX_ERROR_LENGTH = 2000


#: What a scenario argument is: a file, or a bundled one by name.
SCENARIO_HELP = ('scenario YAML file, or the name of a bundled one (allegro_right.yaml, '
                 'planar_two_finger.yaml)')
#: The methods, in words (docs/method.md).
METHOD_HELP = ("tau-qp: the paper's QP over joint torques, the N-gon cones; "
               'tau-qp-adaptive: tau-qp refined towards the exact cone, with a certified '
               'gap; force-qp: the QP over contact forces; socp: the exact cone (Clarabel); '
               'nlp: the exact cone (SciPy)')
#: Exit codes, for --help.
EPILOG = ('exit codes: 0 optimal, 2 bad input (one line on stderr naming the field) or '
          'usage, 3 infeasible (confirmed by an independent LP), 4 nothing certifiable. '
          'Contracts: docs/design.md section 4.')


def _parser() -> argparse.ArgumentParser:
    fmt = HelpFormatter
    parser = argparse.ArgumentParser(prog=PROG, formatter_class=fmt, epilog=EPILOG, description=(
        'Minimum-effort joint torques for a grasp (linearized soft-finger cones, '
        'certified against the exact cone): solve one scenario, compare every method, '
        'or score many candidate grasps.'))
    add_version(parser)
    sub = parser.add_subparsers(dest='command', required=True)
    p_solve = sub.add_parser('solve', help='solve one scenario with one method',
                             formatter_class=fmt, epilog=EPILOG, description=(
                                 'Solve one scenario: the torques, their certificate, and '
                                 'with --json one JSON object (docs/design.md section 4.2).'))
    p_solve.add_argument('scenario', help=SCENARIO_HELP)
    p_solve.add_argument('--method', choices=METHODS, default='tau-qp', help=METHOD_HELP)
    p_solve.add_argument('--backend', choices=BACKENDS, default='proxsuite',
                         help='QP solver of the tau-qp method')
    p_solve.add_argument('--fallback', choices=(*BACKENDS, 'none'), default='daqp',
                         help='backend asked when the first gives nothing certifiable')
    p_solve.add_argument('--gap', type=_gap, default=AdaptiveSettings.gap_tolerance,
                         help='tau-qp-adaptive: stop at this certified gap to the exact '
                              'optimum')
    p_solve.add_argument('--max-rounds', type=_rounds, default=AdaptiveSettings.max_rounds,
                         help='tau-qp-adaptive: refinement rounds at most, 0 to 100')
    p_solve.add_argument('--json', action='store_true', help='print one JSON object')
    p_solve.add_argument('--objective', choices=OBJECTIVES,
                         help="objective instead of the scenario's objective.type")
    p_solve.add_argument('--margin', type=_margin, metavar='K',
                         help="friction margin k >= 0 instead of the scenario's friction.margin: "
                              'plan in the cone of mu/(1+k)')
    p_solve.add_argument('--capacity', action='store_true',
                         help='also the load capacity and the 12 axis capacities')
    p_cmp = sub.add_parser('compare', help="every method side by side (the paper's Table 2)",
                           formatter_class=fmt, epilog=EPILOG, description=(
                               "Every method on one scenario, side by side (the paper's "
                               "Table 2, extended); the exit code is the tau-qp's."))
    p_cmp.add_argument('scenario', help=SCENARIO_HELP)
    p_cmp.add_argument('--json', action='store_true', help='print one JSON object')
    _score_parser(sub)
    from grasp_torque_opt.methods.plan_command import add_parser

    add_parser(sub, HelpFormatter, SCENARIO_HELP, _count)
    return parser


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


def _margin(text: str) -> float:
    try:
        k = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'must be a number, got {text!r}') from None
    if not k >= 0.0 or k == float('inf'):
        raise argparse.ArgumentTypeError(f'must be finite and >= 0, got {text!r}')
    return k


def _count(low: int, high: int):
    """Make an argparse type: an integer in [low, high]."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f'must be an integer, got {text!r}') from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f'must be in [{low}, {high}], got {value}')
        return value
    return parse


def _overridden(setup: GraspSetup, args: argparse.Namespace) -> GraspSetup:
    """Return the setup with the command line's --objective and --margin."""
    if getattr(args, 'objective', None):
        setup = dataclasses.replace(setup, objective=args.objective)
    if getattr(args, 'margin', None) is not None:
        setup = dataclasses.replace(setup, friction=dataclasses.replace(setup.friction,
                                                                        margin=args.margin))
    return setup


def _exit_code(status: str) -> int:
    return {OPTIMAL: EXIT_OPTIMAL, INFEASIBLE: EXIT_INFEASIBLE}.get(status, EXIT_FAILED)


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


def _one_line(text: str) -> str:
    r"""
    Escape every character that is not printable, line breaks included.

    A message quotes the user's input (a path, a name), and str.splitlines()
    breaks a line at \\x85 or \\u2028 as well as at \\n: the error stays one
    line whatever the input holds.
    """
    if len(text) > MAX_ERROR_LENGTH:  # every quoted value is cut already; a last bound
        text = text[:MAX_ERROR_LENGTH - 3] + '...'
    return ''.join(c if c.isprintable() else c.encode('unicode_escape').decode('ascii')
                   for c in text)


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; returns the exit code."""
    try:
        return _main(argv)
    except BrokenPipeError:
        # The reader went away (e.g. `| head`): stop quietly, as Unix tools do, with
        # stdout pointed at /dev/null so that Python's own flush at exit does not fail.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141


def _main(argv: list[str] | None) -> int:
    args = _parser().parse_args(argv)
    single_threaded_math()
    if args.command == 'score':
        return _score(args)
    if args.command == 'plan':
        return _plan(args)
    try:
        setup = _overridden(GraspSetup.from_file(find_config(args.scenario)), args)
        if args.command == 'solve':
            fallback = None if args.fallback in ('none', args.backend) else \
                make_solver(args.fallback)
            refiner = Refiner(AdaptiveSettings(gap_tolerance=args.gap,
                                               max_rounds=args.max_rounds))
            sol = solve(setup, args.method, backend=args.backend, fallback=fallback,
                        refiner=refiner)
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
            return _exit_code(sol.status)
        comparison = compare(setup)
        if args.json:
            print(strict_json({'scenario': args.scenario, **comparison.as_dict()}))
        else:
            print(f'{args.scenario}: {len(setup.hand.joints)} joints, '
                  f'{len(setup.contacts)} contacts, N = {setup.friction.sides}')
            print(format_table(comparison))
        return _exit_code(comparison.solutions['tau-qp'].status)
    except InputError as e:
        print(_one_line(f'{PROG}: error: {args.scenario}: {e}'), file=sys.stderr)
        return EXIT_BAD_INPUT
    except GraspTorqueError as e:
        print(_one_line(f'{PROG}: error: {e}'), file=sys.stderr)
        return EXIT_FAILED
    except (MemoryError, RecursionError) as e:  # the input bounds should make this unreachable
        print(_one_line(f'{PROG}: error: {args.scenario}: scenario: too large to process '
                        f'({type(e).__name__})'), file=sys.stderr)
        return EXIT_BAD_INPUT


def _score_parser(sub) -> None:
    from grasp_torque_opt.methods.ranking import RANK_KEYS
    from grasp_torque_opt.methods.score import ENGINES, METRICS

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
    p.add_argument('--top', type=_count(0, 10**9), default=10,
                   help='rows of the ranked table')
    p.add_argument('--rank-by', choices=tuple(RANK_KEYS), default='capacity',
                   help='capacity (largest first; torque_norm with --metrics basic) or '
                        'torque_norm, max_torque_ratio, friction_usage_max (smallest first)')
    p.add_argument('--metrics', choices=METRICS, default='full',
                   help='full (with the capacities) or basic (solve only)')
    p.add_argument('--workers', type=_count(1, 256), help='processes, 1 to 256 (default: the '
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


def _score(args: argparse.Namespace) -> int:
    from grasp_torque_opt.methods.ranking import format_table, rank, rank_key, record_json, summary
    from grasp_torque_opt.methods.score import read_candidates, score_batch, ScoreJob

    where = args.scenario
    try:
        job = ScoreJob.from_file(find_config(args.scenario), backend=args.backend,
                                 metrics=args.metrics, objective=args.objective,
                                 solutions=args.solutions)
        where = args.candidates
        lines = read_candidates(args.candidates)
        where = args.scenario
        t0 = time.perf_counter()
        records = score_batch(job, lines, workers=args.workers, engine=args.engine,
                              scheduler=args.scheduler,
                              progress=_Progress(not args.no_progress))
        seconds = time.perf_counter() - t0
    except InputError as e:
        print(_one_line(f'{PROG}: error: {where}: {e}'), file=sys.stderr)
        return EXIT_BAD_INPUT
    except (GraspTorqueError, OSError) as e:
        print(_one_line(f'{PROG}: error: {e}'), file=sys.stderr)
        return EXIT_FAILED
    by = rank_key(records, args.rank_by)
    ranked = rank(records, by)
    for i, r in enumerate(ranked, 1):
        r['rank'] = i
    bad = [r for r in records if r['status'] == 'error']
    for r in bad:
        print(_one_line(f"{PROG}: error: {args.candidates}: {r['error']}"), file=sys.stderr)
    if args.out:
        try:
            with open(args.out, 'w') as fh:
                fh.writelines(record_json(r) + '\n' for r in records)
        except OSError as e:
            print(_one_line(f'{PROG}: error: --out: cannot write {args.out}: {e.strerror}'),
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
    return EXIT_BAD_INPUT if bad else EXIT_OPTIMAL


def _plan(args: argparse.Namespace) -> int:
    from grasp_torque_opt.methods.plan_command import run

    try:
        result = run(args)
    except InputError as e:
        print(_one_line(f'{PROG}: error: {args.scenario}: {e}'), file=sys.stderr)
        return EXIT_BAD_INPUT
    except GraspTorqueError as e:
        print(_one_line(f'{PROG}: error: {e}'), file=sys.stderr)
        return EXIT_FAILED
    text = ''.join(line + '\n' for line in result.lines())
    if args.out:
        try:
            Path(args.out).write_text(text)
        except OSError as e:
            print(_one_line(f'{PROG}: error: --out: cannot write {args.out}: {e.strerror}'),
                  file=sys.stderr)
            return EXIT_FAILED
    else:
        sys.stdout.write(text)
    print(result.summary(args.count, args.seed), file=sys.stderr)
    return EXIT_OPTIMAL if len(result.candidates) == args.count else EXIT_INFEASIBLE


if __name__ == '__main__':
    sys.exit(main())
