# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The node's command interfaces, one module each: the certified torque in a driver's units.

The cycle certifies joint torques tau (+ g(q)) [N m]. A hand's driver takes them as
torques (``effort``), as position targets of a servo of known stiffness (``position``), as
motor currents (``current``) or as a feed-forward torque beside a PD (``hybrid``). Each
interface (:class:`~grasp_torque_opt.control.commands.base.CommandInterface`) turns a
certified torque into its :class:`~grasp_torque_opt.control.commands.base.Command`, or
refuses it with a reason that is a fault (never a clip); each has its own settings type,
made from the node's parameters. :data:`~grasp_torque_opt.control.commands.registry.REGISTRY`
lists them (the ``command_interface`` parameter's choices); the node's publishers are
made from the same table (:mod:`grasp_torque_opt.ros.node.outputs`). docs/node.md,
"Command interfaces".
"""
