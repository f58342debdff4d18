# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The composition root: the node's parts, owned in one place.

:class:`GraspTorque` holds the parameters, the grasp, the two controllers, the
inputs, the outputs, the status, tf2 and the ``~/solve`` service. The plain and the
managed node hold one each and differ by its configuration (``managed``): which
command publishers it makes, whether read-only parameters are fixed while
configured, and whether it commands as soon as it is built or only once activated.
"""

from __future__ import annotations

from collections.abc import Callable
import dataclasses
import threading
from typing import Any

from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.control.parameters.validators import check_pairs
from grasp_torque_opt.ros.node import controllers
from grasp_torque_opt.ros.node.declared import DeclaredParameters
from grasp_torque_opt.ros.node.grasp_source import (
    bind,
    bind_scenario,
    Grasp,
    urdf_document,
)
from grasp_torque_opt.ros.node.inputs import Inputs
from grasp_torque_opt.ros.node.outputs import Outputs
from grasp_torque_opt.ros.node.parameters import check_all, hand_context, scenario_defaults
from grasp_torque_opt.ros.node.service import SolveService
from grasp_torque_opt.ros.node.status import GRAPH_STEPS, Status
from grasp_torque_opt.ros.node.tf_gravity import TfGravity
from grasp_torque_opt.ros.peers import PeerWatch
import numpy as np
from rclpy.clock import Clock, ClockType
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.parameter import Parameter


class GraspTorque:
    """
    Every part of the node, and what acts on several of them.

    Attributes:
        node: the rclpy node (plain or lifecycle) the parts use.
        managed: the managed node's configuration (lifecycle publishers, commands
            only while active).
        message_info: inputs are aged from the middleware's receipt time.
        lock: held while the controllers are used or changed.
        controller: the loop's controller (None until built, and after release).
        active: whether it commands once built (the plain node: from the start).
    """

    def __init__(self, node: Node, managed: bool, message_info: bool) -> None:
        """Make the parts; nothing is loaded or started."""
        self.node = node
        self.managed = managed
        self.message_info = message_info
        self.lock = threading.Lock()
        self.controller: TorqueController | None = None
        self.active = not managed
        self.grasp: Grasp | None = None
        self.params: Any = None  # the frozen snapshot the parts run with
        self.last_stamp = None  # header stamp of the last accepted joint state
        self._urdf = ''  # the URDF document loaded ('' for the scenario's hand.urdf)
        self.parameters = DeclaredParameters(node, managed)
        self.peers = PeerWatch()  # what the parts made, checked against the graph
        self.inputs = Inputs(self)
        self.outputs = Outputs(self)
        self.status = Status(self)
        self.service = SolveService(self)
        self.tf = TfGravity()
        self._made: list[tuple[str, Any]] = []
        #: Started by a parameter change (a timer, cancelled until then: rclpy's
        #: EventsExecutor takes no guard conditions): the rule's cycle runs once the
        #: request is applied whole (None while the interfaces are not made).
        self._changed = None
        self._change_due = False

    @property
    def commanding(self) -> bool:
        """Whether the node publishes commands now."""
        return self.active and self.controller is not None

    # -- the grasp and the controllers --------------------------------------------------

    def load(self, stop: Callable[[], bool], joints: list[str] | None = None,
             joints_given: bool = False) -> Grasp:
        """
        Load the URDF, the scenario and its name map.

        ``joints_given``: the ``joints`` parameter was given, to be bound again with it.

        Raises:
            InputError: naming the parameter or the scenario's field.
        """
        value = self.parameters.value
        urdf = urdf_document(self.node, value, stop)
        self._urdf = urdf
        return bind(value('scenario'), value('name_map'), urdf, joints, joints_given)

    def rebind(self, joints: list[str]) -> Grasp:
        """Bind the scenario again, with other actuated joints (the same URDF)."""
        value = self.parameters.value
        return bind(value('scenario'), value('name_map'), self._urdf, joints)

    def defaults(self, grasp: Grasp) -> dict[str, Any]:
        """Give the parameters' defaults from a loaded scenario."""
        return scenario_defaults(grasp.scenario, grasp.setup)

    def build(self, grasp: Grasp) -> None:
        """
        Check every parameter against the hand, then make the two controllers.

        Raises:
            InputError: the first parameter refused, named.
        """
        setup = grasp.setup
        values = self.parameters.values()
        ctx = hand_context(setup.hand, bool(values['torque_limits_above_urdf']))
        ctx = dataclasses.replace(ctx, scenario_object=grasp.scenario.object)
        check_all(values, ctx)
        check_pairs(values, ctx)
        self.parameters.context = ctx
        self.params = p = self.parameters.snapshot()
        self._warn_missing_fallback(p)
        ctrl = controllers.configure(None, setup, p, obj=grasp.scenario.object)
        service = controllers.configure(None, setup, p, service=True, obj=grasp.scenario.object)
        bare = bind_scenario((ctrl, service), grasp.scenario, p, self._urdf)
        if bare:
            self.node.get_logger().warning(bare)
        # The service plans for the model's load (the scenario's, the IMU's): it does not
        # estimate, and a transient correction of the loop's is not its prediction.
        service.solving.estimating = False
        self.grasp = grasp
        self.controller, self.service.controller = ctrl, service
        self.parameters.configured = True

    def apply(self, params: list[Parameter]) -> None:
        """
        Bring both controllers to the parameters after a change (post-set callback).

        The change acts on the command in force (a new certified command, or zeros if the
        one in force is now over the limits) at the next callback of the executor, not at
        the next cycle: rclpy calls this once for each parameter of a set_parameters
        request (unless atomic), and no cycle runs between them, so the rule's cycle
        waits until the whole request is applied (:meth:`on_changed`). Except when the
        command in force exceeds the new torque limits: then the rule runs at once too.
        Not while the node does not command (the managed node's activation runs the same
        rule).
        """
        if self.controller is None:
            return  # nothing loaded yet: configure takes the values
        p = self.parameters.snapshot()
        with self.lock:
            self.params = p
            obj = self.grasp.scenario.object
            controllers.configure(self.controller, self.grasp.setup, p, obj=obj)
            controllers.configure(self.service.controller, self.grasp.setup, p, service=True,
                                  obj=obj)
            if any(x.name == 'solver.fallback' for x in params):
                self._warn_missing_fallback(p)
            if not self.commanding:
                return
            in_force, lim = self.controller.in_force, self.controller.setup.hand.torque_limits
            if in_force is not None and not (np.abs(in_force) <= lim).all():
                # A torque the user has just forbidden is not held until the request ends.
                self._change_due = False
                result = self.controller.reconfigured(self.inputs.now())
                if result is not None:
                    self.outputs.publish(result, self.last_stamp)
            if self._changed is not None:
                self._change_due = True
                self._changed.reset()

    def on_changed(self) -> None:
        """Run the parameter-change rule once a request is applied whole (a one-shot timer)."""
        self._changed.cancel()
        with self.lock:
            if not (self._change_due and self.commanding):
                return
            self._change_due = False
            result = self.controller.reconfigured(self.inputs.now())
            if result is not None:
                self.outputs.publish(result, self.last_stamp)

    def _warn_missing_fallback(self, p: Any) -> None:
        name = p.solver.fallback
        if name != 'none' and not controllers.available(name):
            self.node.get_logger().warning(f'solver.fallback: {name} is not installed (pip '
                                           f'install {name}); running without a fallback '
                                           'backend')

    def cycle_kind(self) -> str:
        """Say which cycle runs: compiled, or Python and why."""
        return controllers.cycle_kind(self.controller)

    def release(self) -> None:
        """Drop the controllers and the model (the managed node's cleanup)."""
        with self.lock:
            self.controller = self.service.controller = None
            self.grasp = None
            self.last_stamp = None
            self.parameters.configured = False
            self.parameters.context = type(self.parameters.context)()

    # -- interfaces -----------------------------------------------------------------------

    def start_interfaces(self) -> None:
        """Make the subscriptions, publishers and timers, and start tf2."""
        made = self._made
        made += [('subscription', s) for s in self.inputs.start()]
        made += self.outputs.start()
        made += [('publisher', p) for p in self.status.start()]
        p = self.params
        # On the steady clock: with use_sim_time and a /clock that stops (or never
        # comes), timers on the ROS clock never fire, and a dead driver's joint states
        # would never be found stale (the staleness itself is judged on the monotonic
        # clock, in the controller).
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        for period, callback in ((p.watchdog_period, self.on_watchdog),
                                 (p.diagnostics_period, self.status.on_diagnostics),
                                 (p.diagnostics_period / GRAPH_STEPS, self.status.on_graph),
                                 (p.marker_period, self.outputs.on_markers)):
            made.append(('timer', self.node.create_timer(period, callback, clock=steady)))
        self._changed = self.node.create_timer(1e-6, self.on_changed, clock=steady)
        self._changed.cancel()
        made.append(('timer', self._changed))
        self.tf.start(self.node)

    def stop_interfaces(self) -> None:
        """Destroy what :meth:`start_interfaces` made."""
        self.tf.stop()
        node = self.node
        for kind, entity in reversed(self._made):
            if kind == 'subscription':
                node.destroy_subscription(entity)
            elif kind == 'timer':
                node.destroy_timer(entity)
            else:
                self.outputs.destroy(kind, entity)
        self._made.clear()
        self._changed, self._change_due = None, False
        self.peers.clear()
        self.outputs.stop()
        self.status.stop()

    def on_watchdog(self) -> None:
        """Check staleness between joint states (the watchdog timer)."""
        if not self.commanding:
            return
        with self.lock:
            result = self.controller.watchdog(self.inputs.now())
            if result is not None:
                self.outputs.publish(result)

    def activate(self) -> None:
        """Start commanding; fresh inputs command at once, a command over the limits zeroed."""
        with self.lock:
            self.active = True
            decision = self.controller.reconfigured(self.inputs.now())
            if decision is not None:
                self.outputs.publish(decision, self.last_stamp)

    def deactivate(self) -> None:
        """Take the safe action of ``fault_policy`` if commanding, then stop commanding."""
        if self.active:
            self.safe_stop()  # while the publishers are still enabled
        with self.lock:
            self.active = False

    def safe_stop(self) -> bool:
        """
        Take the safe action when the node stops commanding, per ``fault_policy``.

        ``zero``: publish zero torques once and wait (up to 0.5 s) for the subscribers
        to acknowledge them, since the effort controller would keep the last command
        forever. ``hold``: nothing (the last certified command stays, as during a
        fault). Nothing either before the first command, nor while the node does not
        command (the managed node took it on deactivate).

        Returns:
            True if zero torques were published.
        """
        with self.lock:
            ctrl = self.controller
            if not self.commanding or ctrl.config.fault_policy != 'zero' or \
                    ctrl.counters.commands == 0 or not self.node.context.ok():
                return False
            m = ctrl.setup.hand.m
            if not self.outputs.publish_zeros(ctrl.policy.interface.zero()):
                return False  # position-like, before a reference was held: nothing to hold
            ctrl.in_force = np.zeros(m)  # what the effort controller holds
        self.outputs.command_pub.wait_for_all_acked(Duration(seconds=0.5))
        self.node.get_logger().info('stopped: zero torques published (fault_policy zero)')
        return True

    def describe(self) -> str:
        """One line for the log: the joints in command order, contacts, topic, cycle."""
        setup = self.grasp.setup
        return (f"{setup.hand.m} joints in command order ({', '.join(setup.hand.joints)}), "
                f'{len(setup.contacts)} default contacts')
