# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The repository's own files, as the lint tests (test_flake8.py and the rest) see them."""

import os
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: Folders at the root that hold other files than the repository's: the virtual environment
#: scripts/setup.sh creates and what setuptools and colcon leave behind.
NOT_OURS = ('.venv', 'build', 'install', 'log')


def not_ours() -> list[str]:
    """Return the absolute paths the linters must leave out, whether they exist or not."""
    return [str(ROOT / d) for d in NOT_OURS] + sorted(str(p) for p in ROOT.glob('*.egg-info'))


def own_files(*suffixes: str) -> list[Path]:
    """
    List the repository's files ending in one of ``suffixes``, in a fixed order.

    Folders named ``.*`` or ``_*`` are left out, as ament's linters leave them out, and so
    are :data:`NOT_OURS` and ``*.egg-info`` at the root.
    """
    out = []
    for folder, dirs, files in os.walk(ROOT):
        here = Path(folder)
        dirs[:] = sorted(d for d in dirs if d[0] not in '._' and not (
            here == ROOT and (d in NOT_OURS or d.endswith('.egg-info'))))
        out += [here / f for f in sorted(files) if f.endswith(suffixes)]
    return out
