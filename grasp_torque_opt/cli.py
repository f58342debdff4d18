"""Command line: ``grasp-torque-opt solve|compare SCENARIO``.

Exit codes: 0 optimal, 3 infeasible, 2 bad input (one line on stderr naming
the field), 4 the solver gave nothing certifiable (no torque is printed).
"""

from __future__ import annotations

import argparse
import json
import sys

from grasp_torque_opt.backends import BACKENDS, make_solver, single_threaded_math
from grasp_torque_opt.core.exceptions import GraspTorqueError, InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.report import solution_dict
from grasp_torque_opt.core.solution import INFEASIBLE, OPTIMAL
from grasp_torque_opt.methods.adaptive import AdaptiveSettings, Refiner
from grasp_torque_opt.methods.compare import compare, format_table
from grasp_torque_opt.methods.dispatch import METHODS, solve

EXIT_OPTIMAL, EXIT_BAD_INPUT, EXIT_INFEASIBLE, EXIT_FAILED = 0, 2, 3, 4
PROG = "grasp-torque-opt"
#: Longest error line [characters].
MAX_ERROR_LENGTH = 2000


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=PROG, description=(
        "Minimum-effort joint torques for a grasp (linearized soft-finger cones, "
        "certified against the exact cone)."))
    sub = parser.add_subparsers(dest="command", required=True)
    p_solve = sub.add_parser("solve", help="solve one scenario with one method")
    p_solve.add_argument("scenario", help="scenario YAML file")
    p_solve.add_argument("--method", choices=METHODS, default="tau-qp")
    p_solve.add_argument("--backend", choices=BACKENDS, default="proxsuite",
                         help="QP solver of the tau-qp method (default: proxsuite)")
    p_solve.add_argument("--fallback", choices=(*BACKENDS, "none"), default="daqp",
                         help="backend asked when the first gives nothing certifiable "
                              "(default: daqp)")
    p_solve.add_argument("--gap", type=_gap, default=AdaptiveSettings.gap_tolerance,
                         help="tau-qp-adaptive: stop at this certified gap to the exact "
                              f"optimum (default: {AdaptiveSettings.gap_tolerance})")
    p_solve.add_argument("--max-rounds", type=_rounds, default=AdaptiveSettings.max_rounds,
                         help="tau-qp-adaptive: refinement rounds at most, 0 to 100 "
                              f"(default: {AdaptiveSettings.max_rounds})")
    p_solve.add_argument("--json", action="store_true", help="print one JSON object")
    p_cmp = sub.add_parser("compare", help="every method side by side (the paper's Table 2)")
    p_cmp.add_argument("scenario", help="scenario YAML file")
    p_cmp.add_argument("--json", action="store_true", help="print one JSON object")
    return parser


def _gap(text: str) -> float:
    value = float(text)
    if not 0.0 < value < 1.0:  # False for NaN as well
        raise argparse.ArgumentTypeError(f"must be in (0, 1), got {text}")
    return value


def _rounds(text: str) -> int:
    value = int(text)
    if not 0 <= value <= 100:
        raise argparse.ArgumentTypeError(f"must be in [0, 100], got {text}")
    return value


def _exit_code(status: str) -> int:
    return {OPTIMAL: EXIT_OPTIMAL, INFEASIBLE: EXIT_INFEASIBLE}.get(status, EXIT_FAILED)


def _print_solution(d: dict) -> None:
    print(f"status: {d['status']} ({d['method']}; {d['message']})")
    if d["tau"] is not None:
        width = max(len(j) for j in d["joints"])
        for name, t in zip(d["joints"], d["tau"]):
            print(f"  {name:<{width}}  {t:+.6f} N m")
        print(f"  ||tau||_2 = {d['torque_norm']:.6f} N m")
    print(f"solve time: {1e3 * d['solve_time_s']:.3f} ms, iterations: {d['iterations']}")
    if d["certificate"] is not None:
        c = d["certificate"]
        print("certificate: " + ", ".join(
            f"{k} {c[k]:.1e}" for k in ("equilibrium", "torque", "cone", "normal_force",
                                        "torque_limit")) + f" (tolerance {c['tolerance']:.0e})")
    b = d.get("bounds")
    if b is not None:
        gap = "-" if b["gap"] is None else f"{100 * b['gap']:.3g}%"
        lower = "none" if b["lower"] is None else f"{b['lower']:.6f}"
        print(f"bounds on the exact optimum of sqrt(tau^T W tau): lower {lower} N m, "
              f"this torque {b['upper']:.6f} N m, gap {gap} ({b['rounds']} rounds, "
              f"{b['qp_solves']} QPs, from {b['source']})" if b["upper"] is not None else
              f"bounds: lower {lower} N m, no certified torque")


def _one_line(text: str) -> str:
    """Escape every character that is not printable, line breaks included.

    A message quotes the user's input (a path, a name), and str.splitlines()
    breaks a line at \\x85 or \\u2028 as well as at \\n: the error stays one
    line whatever the input holds.
    """
    if len(text) > MAX_ERROR_LENGTH:  # every quoted value is cut already; a last bound
        text = text[:MAX_ERROR_LENGTH - 3] + "..."
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii")
                   for c in text)


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; returns the exit code."""
    args = _parser().parse_args(argv)
    single_threaded_math()
    try:
        setup = GraspSetup.from_file(args.scenario)
        if args.command == "solve":
            fallback = None if args.fallback in ("none", args.backend) else \
                make_solver(args.fallback)
            refiner = Refiner(AdaptiveSettings(gap_tolerance=args.gap,
                                               max_rounds=args.max_rounds))
            sol = solve(setup, args.method, backend=args.backend, fallback=fallback,
                        refiner=refiner)
            d = solution_dict(sol, setup.maps())
            if args.json:
                print(json.dumps(d))
            else:
                _print_solution(d)
            return _exit_code(sol.status)
        comparison = compare(setup)
        if args.json:
            print(json.dumps({"scenario": args.scenario, **comparison.as_dict()}))
        else:
            print(f"{args.scenario}: {len(setup.hand.joints)} joints, "
                  f"{len(setup.contacts)} contacts, N = {setup.friction.sides}")
            print(format_table(comparison))
        return _exit_code(comparison.solutions["tau-qp"].status)
    except InputError as e:
        print(_one_line(f"{PROG}: error: {args.scenario}: {e}"), file=sys.stderr)
        return EXIT_BAD_INPUT
    except GraspTorqueError as e:
        print(_one_line(f"{PROG}: error: {e}"), file=sys.stderr)
        return EXIT_FAILED
    except (MemoryError, RecursionError) as e:  # the input bounds should make this unreachable
        print(_one_line(f"{PROG}: error: {args.scenario}: scenario: too large to process "
                        f"({type(e).__name__})"), file=sys.stderr)
        return EXIT_BAD_INPUT


if __name__ == "__main__":
    sys.exit(main())
