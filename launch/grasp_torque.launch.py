# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Start grasp_torque_node beside a ros2_control effort controller.

    ros2 launch grasp_torque_opt grasp_torque.launch.py \
        params_file:=/path/to/my_hand_node.yaml controller:=effort_controller \
        namespace:=right_hand

The node reads its parameters from ``params_file`` (keyed ``/**:``, so they
apply under any node name and namespace), and its ``effort_commands`` are
remapped to ``/<controller>/commands``, the input of an
``effort_controllers/JointGroupEffortController`` whose ``joints`` are the
node's, in the same order (docs/ros2_control.md). ``robot_description``, if
given, is a URDF file whose text becomes the node's ``robot_description``
parameter; otherwise the params file decides (``robot_description_topic``, or
the scenario's ``hand.urdf``). ``managed:=true`` starts the managed (lifecycle)
node ``grasp_torque_lifecycle_node`` instead: it waits unconfigured for a
lifecycle manager (or ``ros2 lifecycle set``) to configure and activate it.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import LifecycleNode, Node

PACKAGE = 'grasp_torque_opt'


def _node(context):
    """Describe the node, with the arguments resolved."""
    params = LaunchConfiguration('params_file').perform(context)
    controller = LaunchConfiguration('controller').perform(context).strip('/')
    urdf = LaunchConfiguration('robot_description').perform(context)
    parameters = [params]
    if urdf:
        with open(urdf) as f:
            parameters.append({'robot_description': f.read()})
    remaps = [('effort_commands', f'/{controller}/commands')] if controller else []
    managed = LaunchConfiguration('managed').perform(context).lower() in ('true', '1')
    action, executable = ((LifecycleNode, 'grasp_torque_lifecycle_node') if managed
                          else (Node, 'grasp_torque_node'))
    return [action(package=PACKAGE, executable=executable, name='grasp_torque_node',
                   namespace=LaunchConfiguration('namespace'), parameters=parameters,
                   remappings=remaps, output='screen', emulate_tty=True)]


def generate_launch_description():
    """Launch arguments, then the node."""
    share = get_package_share_directory(PACKAGE)
    return LaunchDescription([
        DeclareLaunchArgument(
            'params_file', default_value=os.path.join(share, 'config', 'allegro_right_node.yaml'),
            description='Node parameters (YAML keyed /**:); the bundled Allegro file by default'),
        DeclareLaunchArgument(
            'controller', default_value='effort_controller',
            description='JointGroupEffortController whose /<controller>/commands the node '
                        'feeds; empty: publish on effort_commands unremapped'),
        DeclareLaunchArgument('namespace', default_value='',
                              description='Namespace of the node'),
        DeclareLaunchArgument(
            'robot_description', default_value='',
            description='URDF file of the hand; empty: as the params file says '
                        "(robot_description_topic, else the scenario's hand.urdf)"),
        DeclareLaunchArgument(
            'managed', default_value='false',
            description='true: the managed (lifecycle) node grasp_torque_lifecycle_node, '
                        'which commands only once configured and activated; false: the '
                        'plain grasp_torque_node, which commands from its start'),
        OpaqueFunction(function=_node),
    ])
