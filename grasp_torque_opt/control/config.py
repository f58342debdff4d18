# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The cycle's settings: timing, safety limits, the fault policy, the method.

:class:`CycleConfig` is made from the node's parameter schema
(``grasp_torque_node_parameters.yaml``): one frozen field per entry with a ``cycle``
key, with the entry's type and default (:mod:`grasp_torque_opt.control.parameters`).
"""

from grasp_torque_opt.control.parameters import CycleConfig, SCHEMA

#: The fault policies: keep the last certified command, or publish zero torques.
POLICIES = SCHEMA['fault_policy'].choices

__all__ = ['CycleConfig', 'POLICIES']
