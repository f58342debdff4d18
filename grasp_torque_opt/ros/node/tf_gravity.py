# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
tf2 for the gravity and imu inputs: a message's frame in the hand's base frame.

Its listener has a node and an executor thread of its own, in the node's context, so
that /tf traffic never waits behind the control loop (nor holds it). Only when
tf2_ros is importable; not tested here: tf2_ros is not on the package registry.
"""

from __future__ import annotations

import importlib.util
import threading
from typing import Any

from grasp_torque_opt.control.checks import quaternion_matrix
from grasp_torque_opt.core.exceptions import cut, InputError
from grasp_torque_opt.ros import realtime
import numpy as np
import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.time import Time


class TfGravity:
    """A tf2 buffer and listener beside the node, started and stopped with its inputs."""

    def __init__(self) -> None:
        """Hold nothing until :meth:`start`."""
        self._tf: tuple[Any, ...] | None = None  # (buffer, listener, node, executor, thread)

    @property
    def running(self) -> bool:
        """Whether a listener runs."""
        return self._tf is not None

    def start(self, node: Node) -> None:
        """Listen to tf2 beside ``node``, when tf2_ros is importable."""
        if importlib.util.find_spec('tf2_ros') is None:
            return
        import tf2_ros

        tf_node = rclpy.create_node(f'{node.get_name()}_tf_listener',
                                    namespace=node.get_namespace(), context=node.context,
                                    start_parameter_services=False)
        buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(buffer, tf_node, spin_thread=False)
        executor = SingleThreadedExecutor(context=node.context)
        executor.add_node(tf_node)
        thread = threading.Thread(target=_spin, args=(executor,), daemon=True,
                                  name='tf_listener')
        thread.start()
        self._tf = (buffer, listener, tf_node, executor, thread)

    def stop(self) -> None:
        """Stop the listener and its thread."""
        if self._tf is None:
            return
        _, listener, tf_node, executor, thread = self._tf
        self._tf = None
        executor.shutdown(timeout_sec=1.0)
        thread.join(timeout=1.0)
        listener.unregister()
        tf_node.destroy_node()

    def transform(self, base: str, frame: str
                  ) -> tuple[tuple[np.ndarray, np.ndarray] | None, str]:
        """Give the rotation and origin of ``frame`` in ``base`` (latest), or None and why."""
        if self._tf is None:
            return None, 'tf2_ros is not installed'
        import tf2_ros

        try:
            t = self._tf[0].lookup_transform(base, frame, Time())
        except tf2_ros.TransformException as e:
            return None, f'tf2: {cut(str(e))}'
        r, p = t.transform.rotation, t.transform.translation
        try:
            return (quaternion_matrix(np.array([r.x, r.y, r.z, r.w]),
                                      f'{frame} transform'), np.array([p.x, p.y, p.z])), ''
        except InputError as e:
            return None, f'tf2: {e}'

    def rotation(self, base: str, frame: str) -> tuple[np.ndarray | None, str]:
        """Give the rotation from ``frame`` to ``base`` (latest), or None and why not."""
        transform, why = self.transform(base, frame)
        return (None, why) if transform is None else (transform[0], '')


def _spin(executor: SingleThreadedExecutor) -> None:
    realtime.normal_scheduling()  # started by the managed node's (maybe SCHED_FIFO) thread
    try:
        executor.spin()
    except ExternalShutdownException:
        pass
