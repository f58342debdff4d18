# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The node's inputs, one module each, and the store that keeps the latest valid ones.

Each input is a plug-in (:class:`~grasp_torque_opt.control.inputs.base.NodeInput`): its
name (the topic, the counter, the stamp mark), its ROS message type and QoS, a check on
plain arrays that gives the value kept, what it sets in the cycle's snapshot, its
freshness rule and timeout. :data:`~grasp_torque_opt.control.inputs.registry.REGISTRY`
lists them; the store (:mod:`~grasp_torque_opt.control.inputs.store`) takes every one
through one path (check, stamp, reject or keep), and the node's subscriptions are made
from the same table (:mod:`grasp_torque_opt.ros.node.inputs`). Adding an input:
docs/architecture.md, "Where a change belongs".
"""
