# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The ROS 2 adapter: ``grasp_torque_node`` and the demo hand driver.

They are the only modules that import rclpy and message types.
"""
