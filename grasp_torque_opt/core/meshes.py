# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Where a URDF's meshes are: ``package://``, ``file://`` and relative paths made files.

A package is looked up in example-robot-data's share folder (for
``example-robot-data``), then ``share/NAME`` under each ``AMENT_PREFIX_PATH`` entry,
then ``NAME`` under each ``ROS_PACKAGE_PATH`` entry; a relative path is relative to the
URDF's folder. A mesh not found is an error naming it. Shared by the collision model
(:mod:`grasp_torque_opt.core.geometry_contacts`) and the simulation
(:mod:`grasp_torque_opt.sim.robot`).
"""

from __future__ import annotations

import os
from pathlib import Path
import xml.etree.ElementTree as ET

from grasp_torque_opt.core.exceptions import cut, InputError
from grasp_torque_opt.core.hand import example_robot_data_dir

PACKAGE = 'package://'


def package_roots(name: str) -> list[Path]:
    """Folders where ROS package ``name`` may be, in the order they are tried."""
    roots = []
    if name == 'example-robot-data':
        try:
            roots.append(example_robot_data_dir().parent)
        except InputError:
            pass
    for prefix in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep):
        if prefix:
            roots.append(Path(prefix) / 'share' / name)
    for folder in os.environ.get('ROS_PACKAGE_PATH', '').split(os.pathsep):
        if folder:
            roots.append(Path(folder) / name)
    return roots


def resolve_mesh(filename: str, urdf_dir: Path | None) -> Path:
    """
    Return the file a URDF mesh ``filename`` names.

    Raises:
        InputError: not found (field ``hand.urdf``), naming the mesh and where it looked.
    """
    if filename.startswith(PACKAGE):
        name, _, rest = filename[len(PACKAGE):].partition('/')
        roots = package_roots(name)
        for root in roots:
            if (root / rest).is_file():
                return root / rest
        raise InputError('hand.urdf', f"mesh '{cut(filename)}': package '{cut(name)}' not "
                         f'found (looked in {len(roots)} folders: example-robot-data, '
                         'AMENT_PREFIX_PATH, ROS_PACKAGE_PATH)')
    path = Path(filename[len('file://'):] if filename.startswith('file://') else filename)
    if not path.is_absolute() and urdf_dir is not None:
        path = urdf_dir / path
    if not path.is_file():
        raise InputError('hand.urdf', f"mesh '{cut(filename)}' not found")
    return path


def resolve_meshes(root: ET.Element, urdf_dir: Path | None) -> None:
    """Make every collision mesh's filename an absolute path (in place)."""
    for mesh in root.iter('mesh'):
        if mesh.get('filename'):
            mesh.set('filename', str(resolve_mesh(mesh.get('filename'), urdf_dir)))
