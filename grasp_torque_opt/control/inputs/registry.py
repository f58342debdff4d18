# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The node's inputs by name (:data:`REGISTRY`), as the backends' REGISTRY lists solvers.

The order is the order of the staleness rule's reasons (docs/node.md, "Faults"): the
joint states first, then contacts, the external wrench, the object pose, gravity, the IMU,
the tactile input's two forms (one subscribed, by ``tactile.source``).
"""

from __future__ import annotations

from grasp_torque_opt.control.inputs.base import NodeInput
from grasp_torque_opt.control.inputs.contacts import CONTACTS
from grasp_torque_opt.control.inputs.external_wrench import EXTERNAL_WRENCH
from grasp_torque_opt.control.inputs.gravity import GRAVITY
from grasp_torque_opt.control.inputs.imu import IMU
from grasp_torque_opt.control.inputs.joint_states import JOINT_STATES
from grasp_torque_opt.control.inputs.object_pose import OBJECT_POSE
from grasp_torque_opt.control.inputs.tactile import TACTILE, TACTILE_WRENCH

#: Input name -> the input.
REGISTRY: dict[str, NodeInput] = {i.name: i for i in (
    JOINT_STATES, CONTACTS, EXTERNAL_WRENCH, OBJECT_POSE, GRAVITY, IMU, TACTILE, TACTILE_WRENCH)}
#: The inputs counted in ``rejected.*`` from the start (the others from their first
#: rejection: they are optional).
SOURCES = tuple(name for name, i in REGISTRY.items() if i.counted)
