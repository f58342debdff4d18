# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""The node's name and the QoS of its topics and service, named (docs/node.md, "Topics")."""

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

NODE_NAME = 'grasp_torque_node'
#: Commands: reliable, only the newest matters.
COMMAND_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE)
#: joint_states: sensor data QoS (best effort, volatile) with only the newest state kept.
#: When a cycle takes longer than the publisher's period, the next cycle runs on the
#: latest joint state, not on a queue of older ones: with sensor data's keep last 5, the
#: Allegro node at 1 kHz answered 5.5 ms (median) after the stamp here, working off the
#: queue; the other inputs only set state, so their depth costs nothing.
JOINT_STATE_QOS = QoSProfile(depth=1, history=HistoryPolicy.KEEP_LAST,
                             reliability=ReliabilityPolicy.BEST_EFFORT,
                             durability=DurabilityPolicy.VOLATILE)
#: ~/solve: reliable, every request kept until it is taken (keep last 100 dropped 872 to
#: 900 of 1000 concurrent calls silently); the node answers each, "busy" beyond
#: service.MAX_PENDING_SOLVES.
SERVICE_QOS = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE)
#: robot_description as robot_state_publisher publishes it: reliable, transient local.
URDF_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL)
