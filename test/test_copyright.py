# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Every Python and C++ file opens with the copyright and BSD-3-Clause header (ROS template)."""

from pathlib import Path
import re

from lint_files import own_files, ROOT
import pytest

try:
    from ament_copyright.main import main as ament_copyright
except ImportError:  # not on the package registry; in a ROS workspace it is a test_depend
    ament_copyright = None

#: A copyright line as ament_copyright reads one: years (or ranges), then the holder.
COPYRIGHT = re.compile(r'Copyright (\d{4}(-\d{4})?)(, *\d{4}(-\d{4})?)*,? +\S.*', re.IGNORECASE)
#: ament_copyright's bsd_3clause file header (template/bsd_3clause_header_0.txt) after the
#: copyright line, compared with the whitespace normalized, as ament_copyright compares it.
LICENSE_HEADER = ('Use of this source code is governed by a BSD-style license that can be '
                  'found in the LICENSE file or at '
                  'https://developers.google.com/open-source/licenses/bsd')
SPDX = 'SPDX-License-Identifier: BSD-3-Clause'


def header_problem(path: Path) -> str | None:
    """
    Say what is wrong with the header of a Python or C++ file, None if nothing.

    As ament_copyright reads a header: past a shebang or coding line and blank lines, the
    first block of comment lines, a copyright line first, then the licence text. An
    empty file needs none.
    """
    lines = path.read_text(encoding='utf-8').splitlines()
    mark = '#' if path.suffix == '.py' else '//'
    i = 0
    while i < len(lines) and mark == '#' and lines[i].startswith('#') and (
            lines[i].startswith('#!') or 'coding=' in lines[i] or 'coding:' in lines[i]):
        i += 1
    while i < len(lines) and not lines[i].strip():
        i += 1
    block = []
    while i < len(lines) and lines[i].startswith(mark):
        block.append(lines[i][len(mark):].strip())
        i += 1
    if not lines:
        return None
    if not block or not COPYRIGHT.fullmatch(block[0]):
        return 'no copyright line opening the first comment block'
    if LICENSE_HEADER not in ' '.join(' '.join(block[1:]).split()):
        return 'no BSD-3-Clause licence text after the copyright line'
    if SPDX not in block:
        return f'no "{SPDX}" line in the header'
    return None


@pytest.mark.copyright
@pytest.mark.linter
def test_copyright():
    files = own_files('.py', '.cpp', '.hpp', '.h')
    assert ROOT / 'setup.py' in files and ROOT / 'test' / 'test_copyright.py' in files
    assert ROOT / 'src' / 'fast_cycle.hpp' in files
    problems = [f'{p.relative_to(ROOT)}: {why}' for p in files if (why := header_problem(p))]
    assert not problems, 'Files without the copyright header:\n' + '\n'.join(problems)
    if ament_copyright is not None:
        # The files by name: at a repository's root ament_copyright would also hold the
        # LICENSE file to its own wording of the licence and ask for a CONTRIBUTING.md.
        rc = ament_copyright(argv=[str(p) for p in files])
        assert rc == 0, 'Found errors'
