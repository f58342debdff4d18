# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""ament_uncrustify on the compiled cycle's C++ (src/), with ament's configuration."""

import os
from pathlib import Path
import shutil
import sys

from ament_uncrustify.main import main
from lint_files import own_files, ROOT
import pytest


@pytest.mark.uncrustify
@pytest.mark.linter
def test_uncrustify(monkeypatch):
    # In a ROS workspace uncrustify_vendor puts the program on PATH; its wheel (the test
    # extra) installs it under the environment's opt/.
    vendored = Path(sys.prefix) / 'opt' / 'uncrustify_vendor' / 'bin'
    if shutil.which('uncrustify') is None and (vendored / 'uncrustify').is_file():
        monkeypatch.setenv('PATH', f"{vendored}{os.pathsep}{os.environ.get('PATH', '')}")
    assert shutil.which('uncrustify'), 'no uncrustify program (pip install .[test])'
    files = own_files('.cpp', '.hpp', '.h')
    assert ROOT / 'src' / 'fast_cycle.hpp' in files
    rc = main(argv=[str(p) for p in files])
    assert rc == 0, 'Found code style errors (ament_uncrustify --reformat fixes them)'
