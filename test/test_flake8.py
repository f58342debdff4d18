# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""ament_flake8 on the repository, as ``colcon test`` runs it (the ROS package template's test)."""

from ament_flake8.main import main_with_errors
from lint_files import not_ours, ROOT
import pytest


@pytest.mark.flake8
@pytest.mark.linter
def test_flake8(monkeypatch):
    # ament_flake8 leaves out the folders named .* or _* under the working directory (so
    # .venv only when run from the root); the folders of NOT_OURS are left out by path.
    monkeypatch.chdir(ROOT)
    rc, errors = main_with_errors(argv=['.', '--exclude', *not_ours()])
    assert rc == 0, \
        'Found %d code style errors / warnings:\n' % len(errors) + \
        '\n'.join(errors)
