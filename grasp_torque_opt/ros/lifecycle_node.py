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
import time
from typing import Any

from grasp_torque_opt.core.exceptions import GraspTorqueError, InputError
from grasp_torque_opt.ros.node import (
    descriptor,
    fixed_defaults,
    FIXED_WHILE_CONFIGURED,
    GraspTorqueCore,
    NODE_NAME,
    PARAMETERS,
    run,
    scenario_defaults,
    SCENARIO_PARAMETERS,
    stop_requested,
)
from grasp_torque_opt.ros.peers import quiet_publisher
from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn
from rclpy.parameter import Parameter

#: The executable's name.
EXECUTABLE = 'grasp_torque_lifecycle_node'


class GraspTorqueLifecycleNode(GraspTorqueCore, LifecycleNode):
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
        self._init_core(message_info)
        self._active = False
        #: Parameters whose value given at start was refused -> the reason.
        self._refused: dict[str, str] = {}
        #: Parameters that configure filled in from the scenario (emptied at cleanup).
        self._filled: set[str] = set()
        fixed = fixed_defaults()
        for name in PARAMETERS:
            if name == 'name_map':
                self._declare(name, Parameter.Type.STRING_ARRAY)
            elif name in SCENARIO_PARAMETERS:
                self._declare(name, SCENARIO_PARAMETERS[name])
            else:
                self._declare(name, fixed[name])
        self.add_on_set_parameters_callback(self._validate_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)
        self._start_service()
        self.get_logger().info('unconfigured: configure to load the hand, activate to command')

    def _declare(self, name: str, value: Any) -> None:
        """Declare a parameter; a refused value given at start is kept as a reason."""
        try:
            self.declare_parameter(name, value, descriptor(name, managed=True))
        except (InvalidParameterValueException, InvalidParameterTypeException) as e:
            why = str(e).splitlines()[0].split('Reason: ', 1)[-1]  # rclpy's words
            if why.endswith(f': {name}'):
                why = why[:-len(name) - 2]
            self._refused[name] = f'the value given at start was refused ({why})'
            self.declare_parameter(name, value, descriptor(name, managed=True),
                                   ignore_override=True)

    @property
    def commanding(self) -> bool:
        """Whether the node publishes commands now: only while active."""
        return self._active and self.controller is not None

    def _fixed(self, name: str) -> str:
        if PARAMETERS[name].read_only and self.controller is not None and not self._filling:
            return f'{name}: {FIXED_WHILE_CONFIGURED}'
        return ''

    def _apply_parameters(self, params: list[Parameter]) -> None:
        if not self._filling:
            for param in params:  # set by the user: no longer refused, nor the scenario's
                self._refused.pop(param.name, None)
                self._filled.discard(param.name)
        super()._apply_parameters(params)

    def _make_publisher(self, msg_type: type, topic: str, qos: Any) -> Any:
        """Make a command publisher: a lifecycle one, silent unless active."""
        return self.create_lifecycle_publisher(msg_type, topic, qos,
                                               event_callbacks=quiet_publisher())

    def _destroy_command_publisher(self, publisher: Any) -> None:
        self.destroy_lifecycle_publisher(publisher)

    def _state_note(self) -> str:
        return '' if self._active else 'inactive (lifecycle): no commands'

    # -- transitions ----------------------------------------------------------------------

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        """
        Load the URDF, the scenario and its name map; check every parameter.

        Returns:
            SUCCESS (inactive), or FAILURE with one logged line naming what was
            refused (unconfigured again, nothing kept).
        """
        try:
            if self._refused:
                name, why = next(iter(self._refused.items()))
                raise InputError(name, f'{why}; set it, then configure again')
            urdf = self._urdf(stop_requested)
            setup = self._bind(urdf, self._value('joints'))
            self._fill(scenario_defaults(self._scenario, setup))
            self._build(setup)
            self._start_interfaces()
        except GraspTorqueError as e:
            return self._configure_failed(str(e))
        except Exception as e:  # noqa: BLE001 -- a transition fails, it does not raise
            return self._configure_failed(f'{type(e).__name__}: {e}')
        self.get_logger().info(
            f"inactive: {self._m} joints in command order ({', '.join(setup.hand.joints)}), "
            f'{len(setup.contacts)} default contacts; activate to command on '
            f'{self._command_pub.topic_name}; cycle: {self._cycle_kind()}')
        return TransitionCallbackReturn.SUCCESS

    def _configure_failed(self, reason: str) -> TransitionCallbackReturn:
        self.get_logger().error(f'configure failed: {reason}')
        self._unconfigure()
        return TransitionCallbackReturn.FAILURE

    def _fill(self, defaults: dict[str, Any]) -> None:
        """
        Give the parameters still without a value the scenario's.

        Raises:
            InputError: a value refused (it names the parameter).
        """
        self._filling = True
        try:
            for name, value in defaults.items():
                if self._value(name) is not None:
                    continue
                result = self.set_parameters([Parameter(name, value=value)])[0]
                if not result.successful:
                    field, _, problem = result.reason.partition(': ')
                    raise InputError(field, problem)
                self._filled.add(name)
        finally:
            self._filling = False

    def _unconfigure(self) -> None:
        """Release the interfaces and the model; empty what configure filled in."""
        with self._lock:
            self._active = False
        self._stop_interfaces()
        with self._lock:
            self._release()
        self._filling = True
        try:
            for name in sorted(self._filled):
                self.undeclare_parameter(name)
                self.declare_parameter(name, SCENARIO_PARAMETERS[name],
                                       descriptor(name, managed=True), ignore_override=True)
        finally:
            self._filling = False
            self._filled.clear()

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Start commanding: the command publishers are enabled, then the loop commands."""
        result = super().on_activate(state)  # enables the lifecycle publishers
        if result != TransitionCallbackReturn.SUCCESS:
            return result
        with self._lock:
            self._active = True
            # As after a parameter change: fresh inputs command at once, and a command in
            # force over the limits (set while inactive) is zeroed.
            decision = self.controller.reconfigured(time.monotonic())
            if decision is not None:
                self._publish(decision, self._last_stamp)
        self.get_logger().info('active: commanding on each joint state')
        return TransitionCallbackReturn.SUCCESS

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Take the safe action of ``fault_policy``, then stop commanding."""
        self._stop_commanding()
        self.get_logger().info('inactive: no commands')
        return super().on_deactivate(state)  # disables the lifecycle publishers

    def _stop_commanding(self) -> None:
        if self._active:
            self.safe_stop()  # while the publishers are still enabled
        with self._lock:
            self._active = False

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Release the model and the interfaces; unconfigured again."""
        self._unconfigure()
        self.get_logger().info('unconfigured: the hand is released')
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        """From any state: the safe action if active, then release everything."""
        self._stop_commanding()
        self._unconfigure()
        self.get_logger().info('finalized')
        return super().on_shutdown(state)

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        """After an error in a transition: release everything, unconfigured again."""
        self._stop_commanding()
        self._unconfigure()
        self.get_logger().error('a transition raised: the hand is released (unconfigured)')
        return TransitionCallbackReturn.SUCCESS

    def destroy_node(self) -> None:
        """Take the safe action if active, then release everything and stop the node."""
        self._stop_commanding()
        self._stop_interfaces()
        if self._worker is not None:
            self._worker.shutdown(wait=True, cancel_futures=True)
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
