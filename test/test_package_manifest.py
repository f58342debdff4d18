# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""package.xml declares every third-party import of the package, as its rosdep key."""

import ast
from pathlib import Path
import re
import sys
from xml.etree import ElementTree

from lint_files import ROOT

#: Import name -> the rosdep key that installs it in a ROS 2 Jazzy workspace: a Jazzy
#: package's own name (rosdistro's jazzy/distribution.yaml: coal, pinocchio, proxsuite,
#: tf2_ros in geometry2, the message packages) or a key of rosdep/python.yaml.
ROSDEP_KEYS = {
    'numpy': 'python3-numpy',
    'scipy': 'python3-scipy',
    'yaml': 'python3-yaml',
    'pinocchio': 'pinocchio',
    'coal': 'coal',
    'proxsuite': 'proxsuite',
    'tqdm': 'python3-tqdm',
    'PIL': 'python3-pil',
    'matplotlib': 'python3-matplotlib',
    'rclpy': 'rclpy',
    'rcl_interfaces': 'rcl_interfaces',
    'tf2_ros': 'tf2_ros',
    'std_msgs': 'std_msgs',
    'std_srvs': 'std_srvs',
    'sensor_msgs': 'sensor_msgs',
    'geometry_msgs': 'geometry_msgs',
    'visualization_msgs': 'visualization_msgs',
    'diagnostic_msgs': 'diagnostic_msgs',
    'rosgraph_msgs': 'rosgraph_msgs',  # grasp-torque-sim --lockstep's /clock
    'builtin_interfaces': 'builtin_interfaces',
    # launch/grasp_torque.launch.py
    'launch': 'launch',
    'launch_ros': 'launch_ros',
    'ament_index_python': 'ament_index_python',
}

#: Import name -> its pip package, for the imports rosdep has no key for (none in
#: rosdep/python.yaml nor a Jazzy package). Optional: the node runs without them
#: (test/ros/test_without_optional_solvers.py), and docs/ros2_control.md's table says
#: to install them with pip.
PIP_ONLY = {
    'clarabel': 'clarabel',
    'daqp': 'daqp',
    'quadprog': 'quadprog',
    'threadpoolctl': 'threadpoolctl',
    'mujoco': 'mujoco',
    'dask': 'dask',
    'orjson': 'orjson',
}

#: Manifest entries no import names, each with why it is there.
NOT_IMPORTED = {
    # rclpy.lifecycle (the managed node) speaks its services; rclpy does not depend on it.
    'lifecycle_msgs',
}

#: setup.py's build requirements (pyproject.toml [build-system]) -> their rosdep keys, for
#: the compiled cycle; setuptools and wheel come with colcon's ament_python build.
BUILD_KEYS = {'pybind11': 'pybind11-dev', 'cmeel-eigen': 'eigen', 'proxsuite': 'proxsuite',
              'setuptools': None, 'wheel': None}


def third_party_imports(paths: list[Path]) -> dict[str, set[str]]:
    """Map each imported top-level module that is neither stdlib nor ours to its files."""
    found: dict[str, set[str]] = {}
    for path in paths:
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for name in names:
                top = name.split('.')[0]
                if top not in sys.stdlib_module_names and top != 'grasp_torque_opt':
                    found.setdefault(top, set()).add(str(path.relative_to(ROOT)))
    return found


def package_imports() -> dict[str, set[str]]:
    """Return the third-party imports of grasp_torque_opt/ and launch/, at any depth."""
    return third_party_imports(sorted((ROOT / 'grasp_torque_opt').rglob('*.py'))
                               + sorted((ROOT / 'launch').glob('*.py')))


def manifest(*tags: str) -> set[str]:
    """Return the keys package.xml lists under ``tags`` (e.g. exec_depend, depend)."""
    root = ElementTree.parse(ROOT / 'package.xml').getroot()
    return {(e.text or '').strip() for tag in tags for e in root.findall(tag)}


def test_the_scan_sees_the_known_imports():
    # The scan itself: an import inside a function (tf2_ros, coal) counts.
    found = package_imports()
    assert 'grasp_torque_opt/ros/node/tf_gravity.py' in found['tf2_ros']
    assert 'grasp_torque_opt/core/object_geometry.py' in found['coal']
    assert 'os' not in found and 'grasp_torque_opt' not in found


def test_every_third_party_import_is_classified():
    unknown = {m: sorted(f) for m, f in package_imports().items()
               if m not in ROSDEP_KEYS and m not in PIP_ONLY}
    assert not unknown, (
        'imports with neither a rosdep key (ROSDEP_KEYS, and package.xml) nor a pip-only '
        f'entry (PIP_ONLY, and docs/ros2_control.md): {unknown}')


def test_package_xml_declares_every_import_with_a_rosdep_key():
    declared = manifest('depend', 'exec_depend')
    missing = {ROSDEP_KEYS[m]: sorted(f) for m, f in package_imports().items()
               if m in ROSDEP_KEYS and ROSDEP_KEYS[m] not in declared}
    assert not missing, f'package.xml lacks <exec_depend> for: {missing}'


def test_package_xml_declares_nothing_the_package_does_not_use():
    used = {ROSDEP_KEYS[m] for m in package_imports() if m in ROSDEP_KEYS}
    extra = manifest('depend', 'exec_depend') - used - NOT_IMPORTED
    assert not extra, f'package.xml declares keys no import needs: {sorted(extra)}'


def test_the_maps_hold_only_imports_the_package_has():
    # A stale entry would hide a removed dependency.
    found = package_imports()
    stale = sorted(m for m in (*ROSDEP_KEYS, *PIP_ONLY) if m not in found)
    assert not stale, f'mapped but not imported: {stale}'


def test_pip_only_imports_are_in_the_dependencies_table():
    text = (ROOT / 'docs' / 'ros2_control.md').read_text()
    undocumented = sorted(p for p in PIP_ONLY.values() if f'`{p}`' not in text)
    assert not undocumented, f'docs/ros2_control.md does not name: {undocumented}'


def test_build_requirements_are_build_depends():
    # pyproject.toml's one requires list, read without tomllib (Python 3.11+).
    requires = re.search(r'^requires = \[(.*?)\]', (ROOT / 'pyproject.toml').read_text(),
                         re.MULTILINE | re.DOTALL).group(1)
    names = {re.split(r'[<>=!~ ]', r)[0] for r in re.findall(r'"([^"]+)"', requires)}
    unknown = names - set(BUILD_KEYS)
    assert not unknown, f'build requirements without a rosdep key in BUILD_KEYS: {unknown}'
    missing = {BUILD_KEYS[n] for n in names if BUILD_KEYS[n]} - manifest('depend', 'build_depend')
    assert not missing, f'package.xml lacks <build_depend> for: {sorted(missing)}'
