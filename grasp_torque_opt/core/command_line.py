# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
What every console script's ``--help`` and ``--version`` share.

The scripts live in families that may not import each other (``cli`` and ``ros``),
so the help's format and the version option sit here, below both.
"""

from __future__ import annotations

import argparse

from grasp_torque_opt.core.resources import package_version


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """
    argparse's defaults in the help, where there is one to show.

    ``(default: X)`` is added to an option's help unless its default is None or False
    (an absent option, a flag: the help says what then happens) or the help already
    states it.
    """

    def _get_help_string(self, action: argparse.Action) -> str:
        if action.default is None or action.default is False or 'default' in (action.help or ''):
            return action.help or ''
        return super()._get_help_string(action)


def add_version(parser: argparse.ArgumentParser) -> None:
    """Add ``--version``: the program's name and the package's version."""
    parser.add_argument('--version', action='version',
                        version=f'%(prog)s {package_version()} (grasp_torque_opt)')
