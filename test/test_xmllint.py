# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""package.xml and the other XML files: well formed, and package.xml a format 3 manifest."""

import re
import shutil
from xml.etree import ElementTree

from lint_files import NOT_OURS, own_files, ROOT
import pytest

try:
    from ament_xmllint.main import main as ament_xmllint
except ImportError:  # a test_depend in a ROS workspace; the checks here run either way
    ament_xmllint = None

#: The XML files: ament_xmllint checks the *.xml ones, the checks here the URDFs too.
XML_SUFFIXES = ('.xml', '.urdf', '.xacro')


def manifest_problems(root: ElementTree.Element) -> list[str]:
    """List what package.xml lacks of a format 3 manifest (REP 149) that colcon builds."""
    problems = []
    fmt = root.get('format')
    if root.tag != 'package' or fmt != '3':
        problems.append(f'root <{root.tag} format="{fmt}">, not <package format="3">')
    for tag in ('name', 'version', 'description'):
        found = root.findall(tag)
        if len(found) != 1 or not (found[0].text or '').strip():
            problems.append(f'needs exactly one non-empty <{tag}>')
    name = (root.findtext('name') or '').strip()
    if not re.fullmatch(r'[a-z][a-z0-9_]*', name):
        problems.append(f'name {name!r} is not a lower-case ROS package name')
    if not re.fullmatch(r'\d+\.\d+\.\d+', (root.findtext('version') or '').strip()):
        problems.append('version is not MAJOR.MINOR.PATCH')
    maintainers = root.findall('maintainer')
    if not maintainers or not all(m.get('email') and (m.text or '').strip() for m in maintainers):
        problems.append('needs a <maintainer email="..."> with a name')
    if not any((lic.text or '').strip() for lic in root.findall('license')):
        problems.append('needs a <license>')
    if not root.findall('buildtool_depend') and not root.findtext('export/build_type'):
        problems.append('needs a <buildtool_depend> or an <export><build_type>')
    return problems


@pytest.mark.linter
@pytest.mark.xmllint
def test_xmllint(monkeypatch):
    files = own_files(*XML_SUFFIXES)
    assert ROOT / 'package.xml' in files
    problems = []
    for path in files:
        try:
            root = ElementTree.parse(path).getroot()
        except ElementTree.ParseError as e:
            problems.append(f'{path.relative_to(ROOT)}: not well formed: {e}')
            continue
        if path == ROOT / 'package.xml':
            problems += [f'package.xml: {p}' for p in manifest_problems(root)]
    assert not problems, '\n'.join(problems)
    if ament_xmllint is not None and shutil.which('xmllint'):
        # xmllint also validates package.xml against the schema its <?xml-model?> names
        # (fetched from download.ros.org).
        monkeypatch.chdir(ROOT)
        assert ament_xmllint(argv=['.', '--exclude', *NOT_OURS]) == 0, 'Found errors'
