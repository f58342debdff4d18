# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The control cycle on plain arrays and its diagnostics: everything the node does, without ROS.

The cycle covers the input checks, staleness, the gate and the fault policy.
"""
