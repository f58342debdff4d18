# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""``grasp-torque-opt plan SCENARIO``: candidate grasps of an object, as score's lines."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
import sys

from grasp_torque_opt.cli.args import count, numbers, PROG, SCENARIO_HELP
from grasp_torque_opt.core.command_line import (
    EXIT_FAILED,
    EXIT_FEWER,
    EXIT_OK,
    HelpFormatter,
    one_line,
)
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.object_geometry import ObjectShape
from grasp_torque_opt.core.resources import find_config
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.methods.plan import (CONTACT_MODES, ORIENTATIONS, plan_grasps, PlanResult,
                                           PlanSettings, SHAPES)
import numpy as np

#: Sizes of each primitive's ``--size``.
SIZES = {'sphere': 1, 'box': 3, 'cylinder': 2}


def add_parser(sub) -> None:
    """Add ``plan`` to the CLI's subparsers."""
    d = PlanSettings()
    p = sub.add_parser('plan', help='candidate grasps of an object: the contact links on its '
                       'surface (JSON Lines that score reads)', formatter_class=HelpFormatter,
                       description=(
                           'Plan candidate grasps: the object placed in a region about the '
                           "scenario's object origin, an IK puts the contact links on its "
                           'surface and keeps every other link clear; each candidate is a '
                           'line that score reads (docs/planner.md).'),
                       epilog='exit codes: 0 every candidate asked found, 5 fewer found (those '
                       'written), 2 bad input, 4 any other error.')
    p.add_argument('scenario', help=SCENARIO_HELP + ': the hand, friction, torque limits, '
                   'gravity, the grasp the draws start from')
    p.add_argument('--object', choices=tuple(SIZES), help='object shape (default: the '
                   "scenario's object)")
    p.add_argument('--size', type=numbers(None), help='sphere R, box X,Y,Z or cylinder R,L '
                   '[m]')
    p.add_argument('--mesh', help='an object mesh file (.stl, .obj, .dae) instead')
    p.add_argument('--scale', type=float, default=1.0, help="the mesh's units in m")
    p.add_argument('--mass', type=float, help="object mass [kg] (default: the scenario's)")
    p.add_argument('--load', type=numbers(6), metavar='FX,FY,FZ,MX,MY,MZ',
                   help="wrench added to the object's weight [N, N m], base axes")
    p.add_argument('--links', help="contact links, comma-separated (default: the scenario's "
                   "contacts' links; any links with collision shapes, phalanges too)")
    p.add_argument('--count', type=count(1, 100_000), default=d.count, help='candidates')
    p.add_argument('--seed', type=count(0, 2**32 - 1), default=d.seed,
                   help='seed of every draw: the same seed gives the same candidates')
    p.add_argument('--region', type=float, default=d.region, help='half edge of the cube, '
                   "about the scenario's object origin, the object's centre stays in [m]")
    p.add_argument('--centre', type=numbers(3), metavar='X,Y,Z',
                   help="the region's centre [m] (default: the scenario's object origin)")
    p.add_argument('--no-rotate', action='store_true',
                   help="keep the object's axes the base's (else drawn at random)")
    p.add_argument('--orientation', choices=ORIENTATIONS, default=d.orientation,
                   help="a box's or cylinder's orientation: opposed (faces or the curved "
                   "side across the base grasp's thumb and fingers, tilted a little) or "
                   'random (uniform)')
    p.add_argument('--hold-margin', type=float, default=d.hold_margin, metavar='K',
                   help='keep only candidates whose load capacity, with friction margin K '
                   "(or the scenario's, if larger), is at least 1: every load from zero to "
                   'their own held')
    p.add_argument('--keep-unheld', action='store_true',
                   help='keep every candidate that touches, held or not (no --hold-margin)')
    p.add_argument('--clearance', type=float, default=d.clearance,
                   help='every other link at least this far from the object [m]')
    p.add_argument('--tolerance', type=float, default=d.tolerance,
                   help="each contact link within this of the object's surface [m]")
    p.add_argument('--attempts', type=count(1, 1000), default=d.attempts,
                   help='IKs at most per candidate asked')
    p.add_argument('--contacts', choices=CONTACT_MODES, default=d.contacts,
                   help='points: write each point and normal; links: the links only')
    p.add_argument('--shapes', choices=SHAPES, default=d.shapes,
                   help="hand: the hand's own links are kept clear of the object (a robot's "
                   'arm, torso and legs are not read); robot: every link of the URDF')
    p.add_argument('--out', help='write the candidates here (JSON Lines) instead of stdout')


def plan(args: argparse.Namespace) -> PlanResult:
    """
    Plan what the parsed options ask.

    Raises:
        InputError: a bad scenario, object or option (naming it).
    """
    scenario = load_scenario(find_config(args.scenario))
    shape = None
    if args.mesh:
        if args.object or args.size:
            raise InputError('--mesh', 'give either --mesh or --object/--size')
        shape = ObjectShape.mesh_file(args.mesh, args.scale, field='--mesh')
    elif args.object or args.size:
        kind = args.object or (scenario.object.shape if scenario.object else None)
        if kind is None or args.size is None:
            raise InputError('--object', 'give both --object and --size')
        if len(args.size) != SIZES[kind] or min(args.size) <= 0.0:
            raise InputError('--size', f'a {kind} takes {SIZES[kind]} sizes > 0 [m], got '
                             f'{list(args.size)}')
        shape = ObjectShape(kind, np.asarray(args.size, dtype=float), field='--object')
    if args.mass is not None and not (math.isfinite(args.mass) and args.mass > 0.0):
        raise InputError('--mass', f'must be finite and > 0 [kg], got {args.mass!r}')
    settings = PlanSettings(
        count=args.count, seed=args.seed, region=args.region,
        links=tuple(args.links.split(',')) if args.links else None, centre=args.centre,
        rotate=not args.no_rotate, orientation=args.orientation,
        hold_margin=None if args.keep_unheld else args.hold_margin,
        clearance=args.clearance, tolerance=args.tolerance,
        attempts=args.attempts, contacts=args.contacts, extra_load=args.load,
        shapes=args.shapes)
    return plan_grasps(scenario, settings, shape, args.mass)


def run(args: argparse.Namespace) -> int:
    """Plan, write the lines (stdout or --out), the summary on stderr; return the exit code."""
    result = plan(args)
    text = ''.join(line + '\n' for line in result.lines())
    if args.out:
        try:
            Path(args.out).write_text(text)
        except OSError as e:
            print(one_line(f'{PROG}: error: --out: cannot write {args.out}: {e.strerror}'),
                  file=sys.stderr)
            return EXIT_FAILED
    else:
        sys.stdout.write(text)
    print(result.summary(), file=sys.stderr)
    return EXIT_OK if result.complete else EXIT_FEWER
