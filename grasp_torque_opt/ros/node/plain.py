# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
``grasp_torque_node``: the plain node, which loads the grasp and commands from its start.

On each joint state it solves, certifies and publishes one effort command; it
answers ``~/solve`` (docs/node.md). Its parts are in :mod:`grasp_torque_opt.ros.node.root`.
"""

from __future__ import annotations

from typing import Any

from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.ros.node.parameters import PARAMETERS, UNSET_PARAMETERS
from grasp_torque_opt.ros.node.qos import NODE_NAME
from grasp_torque_opt.ros.node.root import GraspTorque
from grasp_torque_opt.ros.node.signals import stop_requested
from rclpy.node import Node


class GraspTorqueNode(Node):
    """Publishes certified effort commands on each joint state; answers ``~/solve``."""

    def __init__(self, message_info: bool = True, **kwargs: Any) -> None:
        """
        Load the scenario and the hand, declare the parameters, start the interfaces.

        Args:
            message_info: age inputs from the middleware's receipt time (rmw message
                info); False: from the callback's time (rclpy 7.1's EventsExecutor
                raises SystemError on subscriptions that take message info).
            kwargs: for rclpy's Node (context, parameter_overrides, ...).

        Raises:
            InputError: a parameter, the scenario or the URDF is refused (named).
        """
        super().__init__(NODE_NAME, **kwargs)
        try:
            self._build(message_info)
        except BaseException:
            # A node refused at start leaves no namesake in the graph for whoever comes
            # next in this process (it would otherwise stay until garbage-collected).
            self.destroy_node()
            raise

    def _build(self, message_info: bool) -> None:
        """Load, declare and start (:meth:`__init__`'s body)."""
        self.root = root = GraspTorque(self, managed=False, message_info=message_info)
        declared = root.parameters
        defaults = PARAMETERS.defaults()
        for name in ('scenario', 'robot_description', 'robot_description_topic',
                     'robot_description_timeout', 'name_map'):
            declared.declare(name, defaults.get(name))
        PARAMETERS.check('name_map', declared.value('name_map'))
        # rclpy has no public way to ask whether a value was given at start.
        grasp = root.load(stop_requested, joints_given='joints' in self._parameter_overrides)
        scenario = root.defaults(grasp)
        joints = declared.declare('joints', scenario.pop('joints'))
        if list(joints) != list(grasp.setup.hand.joints):
            grasp = root.rebind(list(joints))
            scenario = {k: v for k, v in root.defaults(grasp).items() if k != 'joints'}
        for name in PARAMETERS:
            if self.has_parameter(name):
                continue
            if name in scenario or name in defaults:
                declared.declare(name, scenario[name] if name in scenario else defaults[name])
            elif name in UNSET_PARAMETERS:  # a command interface's constants, a list that
                # may stay empty (tactile.links)
                declared.declare(name)
        root.build(grasp)
        declared.watch(root.apply)
        root.start_interfaces()
        root.service.start()
        self.get_logger().info(f'{root.describe()}; commands on '
                               f'{root.outputs.command_pub.topic_name}; cycle: '
                               f'{root.cycle_kind()}')

    @property
    def controller(self) -> TorqueController | None:
        """Give the loop's TorqueController, or None while nothing is loaded."""
        return self.root.controller

    def safe_stop(self) -> bool:
        """Take the safe action of ``fault_policy`` (:meth:`GraspTorque.safe_stop`)."""
        return self.root.safe_stop()

    def destroy_node(self) -> None:
        """Take the safe action, then stop the service worker and the node."""
        self.root.safe_stop()
        self.root.tf.stop()
        self.root.service.shutdown()
        super().destroy_node()
