# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
What the simulated hand driver publishes besides joint states: the palm IMU, the contacts.

Message building only; ``grasp-torque-sim`` (:mod:`~grasp_torque_opt.ros.sim_driver`)
steps the simulation and calls these.
"""

from __future__ import annotations

import numpy as np


def imu_message(Imu, specific_force: np.ndarray, angular_velocity: np.ndarray, frame: str,
                stamp):
    """
    Return a sensor_msgs/Imu of the hand base, as a palm IMU publishes it.

    Args:
        Imu: the message type (sensor_msgs.msg.Imu).
        specific_force: acceleration minus gravity, base axes [m/s^2] (at rest: -g).
        angular_velocity: base axes [rad/s].
        frame: the base frame's name (the message's frame_id).
        stamp: the header stamp.

    No orientation estimate: its covariance's first element is -1 (the message's rule).
    """
    msg = Imu()
    msg.header.frame_id, msg.header.stamp = frame, stamp
    msg.orientation_covariance[0] = -1.0
    a, w = msg.linear_acceleration, msg.angular_velocity
    a.x, a.y, a.z = (float(v) for v in specific_force)
    w.x, w.y, w.z = (float(v) for v in angular_velocity)
    return msg


def publish_contacts(hsim, setup, pub, base, stamp, compute_grasp_maps, Pose, PoseArray
                     ) -> None:
    """
    Publish the contact frames measured in the simulation.

    Each has the measured point and normal, and the x axis from the planned frame at the
    current configuration. Nothing is published while a planned contact does not touch
    (the node's contacts_timeout then applies).
    """
    readings, _ = hsim.readings()
    if not all(r.touching for r in readings):
        return
    q = setup.q.copy()
    q[setup.hand.idx_q] = hsim.q
    maps = compute_grasp_maps(setup.hand, setup.hand.complete(q), setup.contacts,
                              setup.object_origin)
    msg = PoseArray()
    msg.header.frame_id, msg.header.stamp = base, stamp
    for r, R_plan in zip(readings, hsim.sim.base_rotation @ maps.rotations):
        z = r.normal
        x = R_plan[:, 0] - (R_plan[:, 0] @ z) * z
        x /= np.linalg.norm(x)
        R = np.column_stack((x, np.cross(z, x), z))
        qx, qy, qz, qw = quaternion(R)
        pose = Pose()
        pose.position.x, pose.position.y, pose.position.z = (float(v) for v in r.position)
        pose.orientation.x, pose.orientation.y = qx, qy
        pose.orientation.z, pose.orientation.w = qz, qw
        msg.poses.append(pose)
    pub.publish(msg)


def quaternion(R: np.ndarray) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation matrix."""
    import mujoco

    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(R).ravel())
    w, x, y, z = quat
    return float(x), float(y), float(z), float(w)
