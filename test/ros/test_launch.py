# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The launch file, the ros2_control example and the RViz config agree with the node.

``launch`` and ``launch_ros`` are not on the package registry, so the launch file
is checked by parsing it here (its arguments, and that each is documented);
where ``launch_ros`` is importable (a colcon workspace) it is also loaded and
its description built.
"""

import ast
import importlib.util

from conftest import ALLEGRO, CONFIG, ROOT
from grasp_torque_opt.core.grasp_setup import GraspSetup
import pytest
import yaml

LAUNCH = ROOT / 'launch' / 'grasp_torque.launch.py'
DOC = ROOT / 'docs' / 'ros2_control.md'


def launch_arguments() -> dict[str, str]:
    """DeclareLaunchArgument(name, ...) calls of the launch file: name -> description."""
    out = {}
    for node in ast.walk(ast.parse(LAUNCH.read_text())):
        if isinstance(node, ast.Call) and getattr(node.func, 'id', '') == 'DeclareLaunchArgument':
            name = ast.literal_eval(node.args[0])
            kw = {k.arg: k.value for k in node.keywords}
            out[name] = ast.literal_eval(kw['description']) if 'description' in kw else ''
    return out


def test_the_launch_file_declares_its_arguments_and_the_docs_name_each():
    args = launch_arguments()
    assert set(args) == {'params_file', 'controller', 'namespace', 'robot_description',
                         'managed'}
    assert all(args.values()), 'every argument has a description'
    doc = DOC.read_text()
    for name in args:
        assert f'`{name}`' in doc, name


def test_the_executables_the_launch_file_starts_are_installed_by_setup_py():
    """Name both node executables in the launch file as setup.py's entry points name them."""
    source = LAUNCH.read_text()
    scripts = {}
    for node in ast.walk(ast.parse((ROOT / 'setup.py').read_text())):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and \
                ' = grasp_torque_opt.' in node.value:
            name, target = (part.strip() for part in node.value.split('='))
            scripts[name] = target
    assert scripts['grasp_torque_node'] == 'grasp_torque_opt.ros.node:main'
    assert scripts['grasp_torque_lifecycle_node'] == 'grasp_torque_opt.ros.lifecycle_node:main'
    for executable in ('grasp_torque_node', 'grasp_torque_lifecycle_node'):
        assert f"'{executable}'" in source, executable


def test_package_xml_declares_what_the_launch_files_import():
    """Each ROS package a launch file imports is an exec_depend (rosdep installs it)."""
    import sys
    import xml.etree.ElementTree as ET

    declared = {e.text.strip() for e in ET.parse(ROOT / 'package.xml').getroot()
                if e.tag in ('exec_depend', 'depend')}
    for path in (ROOT / 'launch').glob('*.py'):
        imported = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                imported.add(node.module.split('.')[0])
            elif isinstance(node, ast.Import):
                imported.update(a.name.split('.')[0] for a in node.names)
        ros = imported - set(sys.stdlib_module_names) - {'grasp_torque_opt'}
        assert ros, path
        assert ros <= declared, f'{path.name} imports {sorted(ros - declared)} undeclared'


@pytest.mark.skipif(importlib.util.find_spec('launch_ros') is None,
                    reason='launch_ros is absent (not on the package registry)')
def test_the_launch_file_builds_its_description():
    spec = importlib.util.spec_from_file_location('grasp_torque_launch', LAUNCH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    description = module.generate_launch_description()
    names = {a.name for a in description.get_launch_arguments()}
    assert names == set(launch_arguments())


def test_the_effort_controller_has_the_nodes_joints_in_its_order():
    doc = yaml.safe_load((CONFIG / 'allegro_right_controllers.yaml').read_text())
    manager = doc['controller_manager']['ros__parameters']
    assert manager['effort_controller']['type'] == \
        'effort_controllers/JointGroupEffortController'
    params = yaml.safe_load((CONFIG / 'allegro_right_node.yaml').read_text())
    node = next(iter(params.values()))['ros__parameters']
    assert (CONFIG / node['scenario']).resolve() == ALLEGRO.resolve()
    joints = GraspSetup.from_file(ALLEGRO).hand.joints
    assert doc['effort_controller']['ros__parameters']['joints'] == list(joints)


def test_rviz_shows_the_nodes_markers_in_the_hands_base_frame():
    from grasp_torque_opt.ros.node import NODE_NAME

    config = yaml.safe_load((ROOT / 'rviz' / 'grasp_torque.rviz').read_text())
    manager = config['Visualization Manager']
    markers = [d for d in manager['Displays']
               if d['Class'] == 'rviz_default_plugins/MarkerArray']
    assert [d['Topic']['Value'] for d in markers] == [f'/{NODE_NAME}/contact_wrenches']
    assert manager['Global Options']['Fixed Frame'] == \
        GraspSetup.from_file(ALLEGRO).hand.base_frame
