# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""``grasp-torque-opt compare SCENARIO``: every method side by side (the paper's Table 2)."""

from __future__ import annotations

import argparse

from grasp_torque_opt.cli.args import EPILOG, SCENARIO_HELP
from grasp_torque_opt.cli.solve import exit_code
from grasp_torque_opt.core.command_line import HelpFormatter
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.report import strict_json
from grasp_torque_opt.core.resources import find_config
from grasp_torque_opt.methods.compare import compare, format_table


def add_parser(sub) -> None:
    """Add ``compare`` to the CLI's subparsers."""
    p = sub.add_parser('compare', help="every method side by side (the paper's Table 2)",
                       formatter_class=HelpFormatter, epilog=EPILOG, description=(
                           "Every method on one scenario, side by side (the paper's "
                           "Table 2, extended); the exit code is the tau-qp's."))
    p.add_argument('scenario', help=SCENARIO_HELP)
    p.add_argument('--json', action='store_true', help='print one JSON object')


def run(args: argparse.Namespace) -> int:
    """Compare the methods, print the table (or JSON), return the tau-QP's exit code."""
    setup = GraspSetup.from_file(find_config(args.scenario))
    comparison = compare(setup)
    if args.json:
        print(strict_json({'scenario': args.scenario, **comparison.as_dict()}))
    else:
        print(f'{args.scenario}: {len(setup.hand.joints)} joints, '
              f'{len(setup.contacts)} contacts, N = {setup.friction.sides}')
        print(format_table(comparison))
    return exit_code(comparison.solutions['tau-qp'].status)
