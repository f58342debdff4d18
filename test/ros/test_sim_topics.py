# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause
"""The simulated driver's Imu message: specific force and angular velocity, no orientation."""

from builtin_interfaces.msg import Time
from grasp_torque_opt.ros.sim_topics import imu_message
import numpy as np
from sensor_msgs.msg import Imu


def test_the_imu_message_carries_the_base_frame_readings_and_no_orientation():
    stamp = Time(sec=3, nanosec=5)
    msg = imu_message(Imu, np.array([-4.81, 0.5, -1.0]), np.array([0.0, 0.25, -0.125]),
                      'palm_link', stamp)
    assert msg.header.frame_id == 'palm_link' and msg.header.stamp == stamp
    a, w = msg.linear_acceleration, msg.angular_velocity
    assert (a.x, a.y, a.z) == (-4.81, 0.5, -1.0)
    assert (w.x, w.y, w.z) == (0.0, 0.25, -0.125)
    # sensor_msgs/Imu: a first orientation covariance of -1 says there is no orientation.
    assert msg.orientation_covariance[0] == -1.0
