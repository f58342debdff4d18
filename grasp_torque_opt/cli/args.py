# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""What the subcommands' options share: the program's name, help texts, argument types."""

from __future__ import annotations

import argparse
import dataclasses
import math

from grasp_torque_opt.core.grasp_setup import GraspSetup

PROG = 'grasp-torque-opt'
#: What a scenario argument is: a file, or a bundled one by name.
SCENARIO_HELP = ('scenario YAML file, or the name of a bundled one (allegro_right.yaml, '
                 'planar_two_finger.yaml)')
#: Exit codes of solve and compare, for --help.
EPILOG = ('exit codes: 0 optimal, 2 bad input (one line on stderr naming the field) or '
          'usage, 3 infeasible (confirmed by an independent LP), 4 nothing certifiable. '
          'Contracts: docs/design.md section 4.')


def count(low: int, high: int):
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


def numbers(count: int | None):
    """Make an argparse type: ``count`` (None: any number of) comma-separated finite numbers."""
    def parse(text: str) -> tuple[float, ...]:
        try:
            values = tuple(float(v) for v in text.split(','))
        except ValueError:
            raise argparse.ArgumentTypeError(f'must be numbers separated by commas, got '
                                             f'{text!r}') from None
        if (count is not None and len(values) != count) or not all(
                math.isfinite(v) for v in values):
            raise argparse.ArgumentTypeError(f'must be {count or "finite"} numbers separated '
                                             f'by commas, got {text!r}')
        return values
    return parse


def margin(text: str) -> float:
    """Parse a friction margin k: finite and >= 0."""
    try:
        k = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'must be a number, got {text!r}') from None
    if not k >= 0.0 or k == float('inf'):
        raise argparse.ArgumentTypeError(f'must be finite and >= 0, got {text!r}')
    return k


def overridden(setup: GraspSetup, args: argparse.Namespace) -> GraspSetup:
    """Return the setup with the command line's --objective and --margin."""
    if getattr(args, 'objective', None):
        setup = dataclasses.replace(setup, objective=args.objective)
    if getattr(args, 'margin', None) is not None:
        setup = dataclasses.replace(setup, friction=dataclasses.replace(setup.friction,
                                                                        margin=args.margin))
    return setup
