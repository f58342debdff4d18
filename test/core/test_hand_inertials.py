# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
A URDF's masses and inertias are checked before Pinocchio reads them (issue 27, item 7).

urdfdom dropped a NaN inertia (the link's mass became 0, a wrong g(q) certified), took a
negative mass, and printed its own lines on the terminal for both and for a malformed
document.
"""

import os
from pathlib import Path
import re
import subprocess
import sys

from conftest import PLANAR
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.hand import check_inertials, Hand, resolve_urdf
from grasp_torque_opt.core.scenario import load_scenario
import pytest


def planar_urdf() -> str:
    scenario = load_scenario(PLANAR)
    return resolve_urdf(scenario.urdf, scenario.base_dir).read_text()


def first_mass(xml: str, value: str) -> str:
    return re.sub(r'<mass value="[^"]*"', f'<mass value="{value}"', xml, count=1)


@pytest.mark.parametrize('value', ['nan', 'inf', '-1.0', 'heavy'])
def test_a_bad_mass_is_refused_naming_the_link(value):
    with pytest.raises(InputError, match=rf"^robot_description: link 'finger1_proximal': "
                       rf"mass value='{value}' must be a finite number >= 0$"):
        Hand.from_urdf_string(first_mass(planar_urdf(), value))


def test_a_bad_inertia_is_refused_naming_the_link():
    xml = re.sub(r'ixy="[^"]*"', 'ixy="nan"', planar_urdf(), count=1)
    with pytest.raises(InputError, match=r"^robot_description: link '\w+': inertia ixy='nan' "
                       r'must be a finite number$'):
        Hand.from_urdf_string(xml)


def test_good_masses_and_a_massless_link_pass():
    check_inertials(planar_urdf(), 'hand.urdf')
    check_inertials(first_mass(planar_urdf(), '0.0'), 'hand.urdf')


def test_urdfdoms_own_lines_stay_off_the_terminal(tmp_path: Path):
    """A malformed URDF and a NaN mass: one line from the CLI, none of urdfdom's."""
    for name, xml in (('malformed', planar_urdf().replace('</robot>', '<link')),
                      ('nan', first_mass(planar_urdf(), 'nan'))):
        urdf = tmp_path / f'{name}.urdf'
        urdf.write_text(xml)
        code = ('import sys; from grasp_torque_opt.core.hand import Hand\n'
                'try:\n    Hand.from_urdf(sys.argv[1])\n'
                'except Exception as e:\n    print(e, file=sys.stderr); sys.exit(2)\n')
        proc = subprocess.run([sys.executable, '-c', code, str(urdf)], capture_output=True,
                              text=True, timeout=60, env=dict(os.environ))
        assert proc.returncode == 2
        assert len(proc.stderr.splitlines()) == 1, proc.stderr
        assert proc.stderr.startswith('hand.urdf: '), proc.stderr
