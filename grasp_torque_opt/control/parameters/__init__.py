# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The node's parameters, from one schema file, without ROS (the package holds no names).

- :mod:`~grasp_torque_opt.control.parameters.schema`: the loader of
  ``grasp_torque_opt/control/grasp_torque_node_parameters.yaml``
  (generate_parameter_library's format): ``SCHEMA``, the checks that name the
  parameter, the scenario's defaults, the docs table.
- :mod:`~grasp_torque_opt.control.parameters.validators`: the custom checks, small pure
  functions named in the schema, and the rules between parameters.
- :mod:`~grasp_torque_opt.control.parameters.limits`: the bounds the input checks share.
- :mod:`~grasp_torque_opt.control.parameters.generated`: ``CycleConfig`` and the
  ``Params`` snapshot, typed dataclasses written from the schema by
  :mod:`~grasp_torque_opt.control.parameters.generate` (committed; a test fails when
  it is stale).

``python -m grasp_torque_opt.control.parameters`` prints the table of docs/node.md,
"Parameters".
"""
