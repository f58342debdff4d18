# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""ament_pep257 on the repository, as ``colcon test`` runs it (the ROS package template's test)."""

from ament_pep257.main import main
from lint_files import not_ours, ROOT
import pytest

#: Left out on top of the ament convention's list: D406 (a section name ends with a newline),
#: D407 (dashes under a section name) and D413 (a blank line after the last section) are
#: numpy-style section rules. The house style is Google-style sections (``Args:``,
#: ``Returns:``, ``Raises:``, units in brackets), which all three flag.
GOOGLE_SECTIONS = ['D406', 'D407', 'D413']


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257(monkeypatch, capsys):
    monkeypatch.chdir(ROOT)
    rc = main(argv=['.', '--add-ignore', *GOOGLE_SECTIONS, '--exclude', *not_ours()])
    assert rc == 0, 'Found code style errors / warnings:\n' + capsys.readouterr().err
