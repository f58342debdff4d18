# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
A box held by two fingers and a thumb 20 mm off their line (issue 22's example).

Each fingertip is moved by three prismatic joints along the base x, y, z axes, so
J^T is the identity on the contact forces and no torque limit ever conflicts with
friction. The fingers press the box's -x face on the line y = 0, the thumb its +x
face at y = 20 mm: the squeeze makes a moment about z that only tangential forces
can balance, at |f_t| / f_n = offset / width = 0.5, so the grasp holds nothing with
mu 0.3 and holds its load with mu 1.0.
"""

from __future__ import annotations

from pathlib import Path

import yaml

#: Fingertip points [m] (base frame) and their inward normals.
TIPS = {'finger1_tip': ([-0.02, 0.0, 0.02], [1.0, 0.0, 0.0]),
        'finger2_tip': ([-0.02, 0.0, -0.02], [1.0, 0.0, 0.0]),
        'thumb_tip': ([0.02, 0.02, 0.0], [-1.0, 0.0, 0.0])}


def urdf(effort: float = 1000.0) -> str:
    """Return the three-tip hand's URDF, every joint a prismatic one of ``effort`` [N]."""
    parts = ['<?xml version="1.0"?>', '<robot name="box_tips">', '<link name="palm"/>']
    for tip, (pos, _) in TIPS.items():
        stem = tip.replace('_tip', '')
        parent, origin = 'palm', ' '.join(map(str, pos))
        for axis, child in (('1 0 0', f'{stem}_x'), ('0 1 0', f'{stem}_y'),
                            ('0 0 1', tip)):
            parts += [f'<link name="{child}"/>',
                      f'<joint name="{child}_joint" type="prismatic">'
                      f'<parent link="{parent}"/><child link="{child}"/>'
                      f'<origin xyz="{origin}"/><axis xyz="{axis}"/>'
                      f'<limit lower="-1" upper="1" effort="{effort}" velocity="1"/></joint>']
            parent, origin = child, '0 0 0'
    return '\n'.join(parts + ['</robot>'])


def scenario(mu: float = 0.3, flip: str | None = None) -> dict:
    """
    Return the scenario document (its URDF at ``box_tips.urdf`` beside it).

    Args:
        mu: the tangential friction coefficient [-].
        flip: a tip whose normal is written pointing out of the box.
    """
    contacts = [{'link': tip, 'normal': [-n for n in normal] if tip == flip else normal}
                for tip, (_, normal) in TIPS.items()]
    return {'hand': {'urdf': 'box_tips.urdf', 'torque_limits': 1000.0},
            'grasp': {'object_origin': [0.0, 0.0, 0.0], 'contacts': contacts},
            'friction': {'mu_tangential': mu, 'mu_torsional': 0.001, 'polygon_sides': 8,
                         'min_normal_force': 1.0},
            'load': {'external_wrench': [0.0, 0.0, -1.0, 0.0, 0.0, 0.0]},
            'object': {'shape': 'box', 'size': [0.04, 0.08, 0.08], 'mass': 0.1}}


def write(folder: Path, doc: dict, name: str = 'box.yaml') -> Path:
    """Write the URDF and the scenario document into ``folder``; return the scenario."""
    (folder / 'box_tips.urdf').write_text(urdf())
    path = folder / name
    path.write_text(yaml.safe_dump(doc))
    return path
