# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
ROS 2 node ``grasp_torque_node``: certified grasp torques every cycle, and a solve service.

A thin adapter over :class:`grasp_torque_opt.control.controller.TorqueController`,
made of small parts (docs/architecture.md, "The node's parts"):

- :mod:`.parameters` and :mod:`.declared`: the parameters from the one schema
  (``grasp_torque_opt/control/grasp_torque_node_parameters.yaml``), declared and checked;
- :mod:`.grasp_source`: the URDF, the scenario and the name map;
- :mod:`.controllers`: the two controllers made from the parameters (start and change);
- :mod:`.inputs`, :mod:`.tf_gravity`: subscriptions, messages to plain arrays, tf2;
- :mod:`.outputs`, :mod:`.status`: commands, markers, /diagnostics;
- :mod:`.service`: ``~/solve`` and its worker;
- :mod:`.root`: the composition root that owns the parts (plain or managed);
- :mod:`.plain`: the plain node; :mod:`.runner` and :mod:`.signals`: running it.

Interface pinned in docs/node.md (what of it is stable: docs/design.md section 5).
"""

from grasp_torque_opt.ros.node.grasp_source import wait_for_urdf
from grasp_torque_opt.ros.node.parameters import descriptor, PARAMETERS
from grasp_torque_opt.ros.node.plain import GraspTorqueNode
from grasp_torque_opt.ros.node.qos import (
    COMMAND_QOS,
    JOINT_STATE_QOS,
    NODE_NAME,
    SERVICE_QOS,
    URDF_QOS,
)
from grasp_torque_opt.ros.node.runner import main, run
from grasp_torque_opt.ros.node.service import MAX_PENDING_SOLVES

__all__ = ['COMMAND_QOS', 'descriptor', 'GraspTorqueNode', 'JOINT_STATE_QOS',
           'main', 'MAX_PENDING_SOLVES', 'NODE_NAME', 'PARAMETERS', 'run', 'SERVICE_QOS',
           'URDF_QOS', 'wait_for_urdf']
