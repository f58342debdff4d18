# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Every relative link of the top-level *.md and docs/*.md leads to a file and heading."""

from pathlib import Path
import re

ROOT = Path(__file__).resolve().parents[1]
PAGES = [*sorted(ROOT.glob('*.md')), *sorted((ROOT / 'docs').glob('*.md'))]
LINK = re.compile(r'\]\((?P<target>[^)\s]+)\)')
#: Pages linked before they land (none now).
PENDING: set[Path] = set()


def slug(heading: str) -> str:
    """Return GitHub's anchor for a heading: lower case, punctuation dropped, spaces to -."""
    text = re.sub(r'[`*]', '', heading.strip().lower())
    return re.sub(r'[^\w\- ]', '', text).replace(' ', '-')


def anchors(page: Path) -> set[str]:
    """Return the anchors of a page's headings (outside fenced blocks)."""
    found, fenced = set(), False
    for line in page.read_text(encoding='utf-8').splitlines():
        if line.lstrip().startswith(('```', '~~~')):
            fenced = not fenced
        elif not fenced and line.startswith('#'):
            found.add(slug(line.lstrip('#')))
    return found


def test_relative_links_lead_somewhere():
    """Name each relative link whose file or heading does not exist."""
    broken = []
    for page in PAGES:
        for match in LINK.finditer(page.read_text(encoding='utf-8')):
            target = match['target']
            if re.match(r'[a-z]+:', target):
                continue
            path, _, anchor = target.partition('#')
            file = (page.parent / path).resolve() if path else page
            if file in PENDING:
                continue
            if not file.exists():
                broken.append(f'{page.name}: {target} (no such file)')
            elif anchor and file.suffix == '.md' and anchor not in anchors(file):
                broken.append(f'{page.name}: {target} (no such heading)')
    assert not broken, 'broken links:\n' + '\n'.join(broken)
