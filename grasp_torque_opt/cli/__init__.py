# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Command line: ``grasp-torque-opt solve|compare|plan|init-node SCENARIO``, ``... score CANDIDATES``.

One module per subcommand (:data:`COMMANDS`), each with ``add_parser(sub)`` and
``run(args) -> exit code``; every error becomes its exit code by one table,
:data:`grasp_torque_opt.core.command_line.ERRORS` (0 optimal, 2 bad input with one
line on stderr naming the field, 3 infeasible, 4 nothing certifiable or any other
error of the package, 5 fewer candidates planned than asked).
"""

from __future__ import annotations

import argparse

from grasp_torque_opt.backends import single_threaded_math
from grasp_torque_opt.cli import compare, init_node, plan, score, solve
from grasp_torque_opt.cli.args import EPILOG, PROG
from grasp_torque_opt.core.command_line import add_version, HelpFormatter, run_command

#: Subcommand -> its module, in the order of --help.
COMMANDS = {'solve': solve, 'compare': compare, 'score': score, 'plan': plan,
            'init-node': init_node}


def parser() -> argparse.ArgumentParser:
    """Return the command line's parser, every subcommand's options in it."""
    p = argparse.ArgumentParser(prog=PROG, formatter_class=HelpFormatter, description=(
        'Minimum-effort joint torques for a grasp (linearized soft-finger cones, '
        'certified against the exact cone): solve one scenario, compare every method, '
        'or score many candidate grasps.'), epilog=EPILOG)
    add_version(p)
    sub = p.add_subparsers(dest='command', required=True)
    for module in COMMANDS.values():
        module.add_parser(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; returns the exit code."""
    args = argparse.Namespace(where=None)

    def body() -> int:
        parser().parse_args(argv, namespace=args)
        if args.where is None and hasattr(args, 'scenario') and args.command != 'score':
            args.where = args.scenario
        single_threaded_math()
        return COMMANDS[args.command].run(args)

    return run_command(PROG, body, lambda: args.where)
