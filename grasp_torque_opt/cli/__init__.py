# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Command line: ``grasp-torque-opt solve|compare|plan|init-node SCENARIO``, ``... score CANDIDATES``.

One module per subcommand (:data:`COMMANDS`, imported when it is asked), each with
``add_parser(sub)`` and ``run(args) -> exit code``; every error becomes its exit code by one table,
:data:`grasp_torque_opt.core.command_line.ERRORS` (0 optimal, 2 bad input with one
line on stderr naming the field, 3 infeasible, 4 nothing certifiable or any other
error of the package, 5 fewer candidates planned than asked).
"""

from __future__ import annotations

import argparse
import importlib
import sys

from grasp_torque_opt.cli.args import EPILOG, PROG
from grasp_torque_opt.core.command_line import add_version, HelpFormatter, run_command

#: The subcommands: name -> its module in this package.
COMMANDS = {'solve': 'solve', 'compare': 'compare', 'score': 'score', 'plan': 'plan',
            'init-node': 'init_node'}


def command_module(name: str):
    """Return subcommand ``name``'s module (imported on first use)."""
    return importlib.import_module(f'{__name__}.{COMMANDS[name]}')


def parser(command: str | None = None) -> argparse.ArgumentParser:
    """
    Return the command line's parser: every subcommand's options, or ``command``'s alone.

    A subcommand's module (and what it imports: solvers, the node's schema) is imported
    only for its options: ``plan`` starts without ``solve``'s and ``init-node``'s
    imports, about a tenth of a second (issue 36). The others are then listed by name.
    """
    p = argparse.ArgumentParser(prog=PROG, formatter_class=HelpFormatter, description=(
        'Minimum-effort joint torques for a grasp (linearized soft-finger cones, '
        'certified against the exact cone): solve one scenario, compare every method, '
        'or score many candidate grasps.'), epilog=EPILOG)
    add_version(p)
    sub = p.add_subparsers(dest='command', required=True)
    for name in COMMANDS:
        if command in (None, name):
            command_module(name).add_parser(sub)
        else:
            sub.add_parser(name)
    return p


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; returns the exit code."""
    args = argparse.Namespace(where=None)

    def body() -> int:
        # The first word names the subcommand; an option first (--help, --version) is the
        # top level's, whose help lists every subcommand with its line.
        words = sys.argv[1:] if argv is None else argv
        named = words[0] if words and words[0] in COMMANDS else None
        parser(named).parse_args(argv, namespace=args)
        if args.where is None and hasattr(args, 'scenario') and args.command != 'score':
            args.where = args.scenario
        from grasp_torque_opt.backends import single_threaded_math

        single_threaded_math()
        return command_module(args.command).run(args)

    return run_command(PROG, body, lambda: args.where)
