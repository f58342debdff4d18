# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""ament_cpplint on the compiled cycle's C++ (src/), as ``colcon test`` runs it for C++."""

from ament_cpplint.main import main
from lint_files import own_files, ROOT
import pytest


@pytest.mark.cpplint
@pytest.mark.linter
def test_cpplint():
    files = own_files('.cpp', '.hpp', '.h')
    assert ROOT / 'src' / 'fast_cycle.hpp' in files
    rc = main(argv=[str(p) for p in files])
    assert rc == 0, 'Found code style errors / warnings'
