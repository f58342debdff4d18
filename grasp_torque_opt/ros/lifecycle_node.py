# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The managed (lifecycle) ``grasp_torque_node``, executable ``grasp_torque_lifecycle_node``.

The same node as :class:`grasp_torque_opt.ros.node.GraspTorqueNode` (topics,
parameters, service, fault policy), driven by the standard lifecycle services
(``~/change_state``, ``~/get_state``, ...) as ros2_control users expect
(docs/node.md, "Plain or managed"):

- **unconfigured** (at start): parameters declared, nothing loaded; a parameter
  that is read-only in the plain node can be set; ``~/solve`` says it cannot solve.
- **configure**: the URDF (``robot_description``, else the one published on
  ``robot_description_topic``, waited for up to ``robot_description_timeout``, else
  the scenario's), the scenario and its name map, every parameter checked; the
  scenario's defaults fill the parameters still without a value. A refusal is one
  logged line naming the parameter, and the transition fails (back to unconfigured).
- **inactive**: inputs are taken and checked, ``~/solve`` solves, /diagnostics says
  STALE "inactive"; no command is published.
- **activate**: commands flow on each joint state (a fresh one already taken
  commands at once); the parameter-change rule runs on the command in force.
- **deactivate** and **shutdown** (from active): the safe action of
  ``fault_policy`` (``zero``: zero torques, acknowledged; ``hold``: nothing), then
  no command follows.
- **cleanup**: the model and the interfaces are released; parameters filled in from
  the scenario are emptied again, so that the next configure takes the new URDF's.
"""

from __future__ import annotations

import sys
from typing import Any

from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.core.exceptions import GraspTorqueError
from grasp_torque_opt.ros.node.qos import NODE_NAME
from grasp_torque_opt.ros.node.root import GraspTorque
from grasp_torque_opt.ros.node.runner import run
from grasp_torque_opt.ros.node.signals import stop_requested
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn

#: The executable's name.
EXECUTABLE = 'grasp_torque_lifecycle_node'


class GraspTorqueLifecycleNode(LifecycleNode):
    """The node, managed: it loads at configure and commands only while active."""

    def __init__(self, message_info: bool = True, **kwargs: Any) -> None:
        """
        Declare every parameter; load nothing (unconfigured).

        A value given at start that rclpy refuses (out of its range, of another
        type) does not end the node: the parameter keeps its default (or stays
        without a value), and configure fails naming it until it is set.

        Args:
            message_info: age inputs from the middleware's receipt time (rmw message
                info); False: from the callback's time (rclpy 7.1's EventsExecutor).
            kwargs: for rclpy's LifecycleNode (context, parameter_overrides, ...).
        """
        super().__init__(NODE_NAME, **kwargs)
        self.root = GraspTorque(self, managed=True, message_info=message_info)
        self.root.parameters.declare_all_managed()
        self.root.parameters.watch(self.root.apply)
        self.root.service.start()
        self.get_logger().info('unconfigured: configure to load the hand, activate to command')

    @property
    def controller(self) -> TorqueController | None:
        """Give the loop's TorqueController, or None while unconfigured."""
        return self.root.controller

    def safe_stop(self) -> bool:
        """Take the safe action of ``fault_policy`` (:meth:`GraspTorque.safe_stop`)."""
        return self.root.safe_stop()

    # -- transitions ----------------------------------------------------------------------

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        """
        Load the URDF, the scenario and its name map; check every parameter.

        Returns:
            SUCCESS (inactive), or FAILURE with one logged line naming what was
            refused (unconfigured again, nothing kept).
        """
        root = self.root
        try:
            root.parameters.first_refused()
            grasp = root.load(stop_requested, root.parameters.value('joints'))
            root.parameters.fill(root.defaults(grasp))
            root.build(grasp)
            root.start_interfaces()
        except GraspTorqueError as e:
            return self._configure_failed(str(e))
        except Exception as e:  # noqa: BLE001 -- a transition fails, it does not raise
            return self._configure_failed(f'{type(e).__name__}: {e}')
        self.get_logger().info(
            f'inactive: {root.describe()}; activate to command on '
            f'{root.outputs.command_pub.topic_name}; cycle: {root.cycle_kind()}')
        return TransitionCallbackReturn.SUCCESS

    def _configure_failed(self, reason: str) -> TransitionCallbackReturn:
        self.get_logger().error(f'configure failed: {reason}')
        self._unconfigure()
        return TransitionCallbackReturn.FAILURE

    def _unconfigure(self) -> None:
        """Release the interfaces and the model; empty what configure filled in."""
        root = self.root
        with root.lock:
            root.active = False
        root.stop_interfaces()
        root.release()
        root.parameters.empty_filled()

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Start commanding: the command publishers are enabled, then the loop commands."""
        result = super().on_activate(state)  # enables the lifecycle publishers
        if result != TransitionCallbackReturn.SUCCESS:
            return result
        # As after a parameter change: fresh inputs command at once, and a command in
        # force over the limits (set while inactive) is zeroed.
        self.root.activate()
        self.get_logger().info('active: commanding on each joint state')
        return TransitionCallbackReturn.SUCCESS

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Take the safe action of ``fault_policy``, then stop commanding."""
        self.root.deactivate()
        self.get_logger().info('inactive: no commands')
        return super().on_deactivate(state)  # disables the lifecycle publishers

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Release the model and the interfaces; unconfigured again."""
        self._unconfigure()
        self.get_logger().info('unconfigured: the hand is released')
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        """From any state: the safe action if active, then release everything."""
        self.root.deactivate()
        self._unconfigure()
        self.get_logger().info('finalized')
        return super().on_shutdown(state)

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        """After an error in a transition: release everything, unconfigured again."""
        self.root.deactivate()
        self._unconfigure()
        self.get_logger().error('a transition raised: the hand is released (unconfigured)')
        return TransitionCallbackReturn.SUCCESS

    def destroy_node(self) -> None:
        """Take the safe action if active, then release everything and stop the node."""
        self.root.deactivate()
        self.root.stop_interfaces()
        self.root.service.shutdown()
        super().destroy_node()
        # rclpy 7.1's LifecycleNode leaves its state machine, which holds the node's
        # handle: the node stayed on the domain's graph after destroy_node() (and a
        # node of its name started later saw it as a namesake) until the process ended.
        self._state_machine.destroy_when_not_in_use()


def main(args: list[str] | None = None) -> int:
    """Run the managed node (unconfigured until a lifecycle manager configures it)."""
    return run(GraspTorqueLifecycleNode, EXECUTABLE, args)


if __name__ == '__main__':
    sys.exit(main())
