# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The control cycle, free of ROS: inputs checked and timed, solve, certify, gate, fault policy.

The node (:mod:`grasp_torque_opt.ros.node`) only converts messages to the plain
arrays taken here and publishes what :meth:`TorqueController.cycle` and
:meth:`TorqueController.watchdog` return.

Fault policy (docs/node.md, "Faults"): a command is published only from a certified
solution that passes the gate (finite, one value per joint, within the torque
limits). When a cycle cannot produce one (stale or invalid input, failed solve
or certificate), nothing new is published: the effort controller keeps the
last certified command. Once ``hold_time`` has passed since that command, the
policy applies: ``hold`` keeps publishing nothing (the hand keeps its last
certified torques), ``zero`` publishes zero torques. The first certified
solution after a fault is published at once (recovery).

A cycle that fails in any way (a solver that raises, a status other than
solved, a certificate that fails, an unexpected exception) is such a fault; so
is a cycle that overruns ``cycle_budget``: its command is late and is dropped.
The solvers are given the cycle's budget (:meth:`TorqueController.budget`) as
a deadline that they keep themselves, so a cycle ends within about its budget
whatever the parameters; and the inputs are checked fresh again when the
command leaves, not only when the cycle starts. A controller run in simulated time
(``untimed``, the simulation's in-process node) gives its solvers no deadline (their
iteration caps only) and lets its wall time decide nothing: its commands then depend
on its inputs alone, not on the machine's load.

Input rules (docs/node.md, "Faults" and "Input checks"): every message is checked
whole before it is kept (sizes, names, finite values, unit quaternions, known
frames, magnitudes, header stamps); a rejected message changes nothing.

:class:`TorqueController` composes three parts: the input store
(:mod:`~grasp_torque_opt.control.inputs`, with the checks of
:mod:`~grasp_torque_opt.control.checks`), the solve (:mod:`~grasp_torque_opt.control.cycle`)
and the fault policy (:mod:`~grasp_torque_opt.control.fault_policy`).
"""

from __future__ import annotations

import copy
from operator import attrgetter
import time
from typing import Any

from grasp_torque_opt.backends import make_solver
from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings
from grasp_torque_opt.control.cycle import Cycle
from grasp_torque_opt.control.fault_policy import CycleResult, FaultPolicy
from grasp_torque_opt.control.geometry import placements_at
from grasp_torque_opt.control.inputs.store import Counters, Inputs, InputStore
from grasp_torque_opt.control.parameters.generated import CycleConfig
from grasp_torque_opt.control.rates import slewed, step_wrenches, within_step
from grasp_torque_opt.control.tactile import tactile_report, TactileReport
from grasp_torque_opt.core.friction import cone_margin
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.solution import Solution
import numpy as np

#: How far a rate-rule step's contact wrenches may lie outside the exact cone [N]: the
#: certificate's tolerance (a convex combination of two certified wrenches is inside).
STEP_CONE_TOLERANCE = 1e-6


class _In:
    """An attribute of the controller that one of its parts holds (read and set there)."""

    def __init__(self, part: str) -> None:
        self.part = part

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name
        self._get = attrgetter(f'{self.part}.{name}')

    def __get__(self, obj, objtype=None):
        return self if obj is None else self._get(obj)

    def __set__(self, obj, value) -> None:
        setattr(obj.__dict__[self.part], self.name, value)


class _Shared:
    """An attribute every part holds: set on the controller, it is set on each part."""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name
        self._get = attrgetter(f'policy.{name}')

    def __get__(self, obj, objtype=None):
        return self if obj is None else self._get(obj)

    def __set__(self, obj, value) -> None:
        for part in ('store', 'solving', 'policy'):
            setattr(obj.__dict__[part], self.name, value)


class TorqueController:
    """
    The cycle of the node, on plain arrays: the input store, the solve and the fault policy.

    Args:
        setup: the grasp of the scenario: hand, default contacts and load,
            friction, limits, weights. Its hand is owned by this controller.
        config: timing and safety settings.
        solver_settings: solver tolerance and iteration caps (converted to each
            backend's own settings by :func:`~grasp_torque_opt.backends.make_solver`).
        backend: QP backend, one of :data:`grasp_torque_opt.backends.BACKENDS`.
        warm_start: start each solve from the previous one (ProxSuite and DAQP;
            verified, with a cold redo in the same cycle).
        fallback: a second backend, asked in the same cycle when the first gives
            nothing certifiable; None for none.

    Attributes:
        store: the input store (:class:`~grasp_torque_opt.control.inputs.InputStore`).
        solving: the solve (:class:`~grasp_torque_opt.control.cycle.Cycle`).
        policy: the fault policy (:class:`~grasp_torque_opt.control.fault_policy.FaultPolicy`).
    """

    #: Simulated time (the simulation's in-process node, ros/sim_compare): no deadline for
    #: the solvers and no decision by the cycle's wall time (module docstring).
    untimed = False
    #: The grasp, the settings and the running totals: every part's, set on all at once.
    setup = _Shared()
    config = _Shared()
    counters = _Shared()
    #: The input store's: the latest valid inputs and the last rejection's reason.
    inputs = _In('store')
    last_rejection = _In('store')
    #: The solve's: backends, tau-qp-adaptive's refiner, the load of a gravity input, the
    #: compiled cycle and why it is not used.
    solver = _In('solving')
    fallback = _In('solving')
    refiner = _In('solving')
    load_of_gravity = _In('solving')
    compiled_cycle = _In('solving')
    compiled_reason = _In('solving')
    #: The last certified command's contacts against the tactile readings
    #: (:class:`~grasp_torque_opt.control.tactile.TactileReport`; None: no tactile source,
    #: or no command yet): ``tactile.usage`` is the measured friction usage per contact.
    tactile = _In('solving')
    #: The fault policy's: the fault, the last certified command and its time, the
    #: command in force, the last result.
    fault = _In('policy')
    last_command = _In('policy')
    last_command_time = _In('policy')
    in_force = _In('policy')
    last = _In('policy')

    def __init__(self, setup: GraspSetup, config: CycleConfig | None = None,
                 solver_settings: ProxSuiteSettings | None = None,
                 backend: str = 'proxsuite', warm_start: bool = False,
                 fallback: str | None = None) -> None:
        config = config or CycleConfig()
        counters = Counters()
        solver = make_solver(backend, solver_settings, warm_start)
        second = make_solver(fallback, solver_settings) if fallback else None
        self.store = InputStore(setup, config, counters)
        self.solving = Cycle(setup, config, counters, solver, second)
        self.policy = FaultPolicy(setup, config, counters)

    def __copy__(self) -> TorqueController:
        """
        Return a shallow copy that keeps the setup, settings and state of now.

        Its parts are shallow copies of these: a later parameter change (a new setup or
        config set on this controller) does not reach the copy, as for any shallow copy.
        """
        new = object.__new__(type(self))
        new.store, new.solving, new.policy = (copy.copy(part) for part in (
            self.store, self.solving, self.policy))
        new.untimed = self.untimed
        return new

    # -- inputs: the store's ---------------------------------------------------------------

    def check_bytes(self, source: str, n: int) -> None:
        """Reject a message by its serialized length (:meth:`InputStore.check_bytes`)."""
        self.store.check_bytes(source, n)

    def check_size(self, source: str, n: int, frame_id: str = '') -> None:
        """Reject a message by its size alone (:meth:`InputStore.check_size`)."""
        self.store.check_size(source, n, frame_id)

    def take(self, source: str, reading: Any, now: float, stamp: float = 0.0,
             clock: float | None = None) -> None:
        """Take a message of the input ``source``, or reject it (:meth:`InputStore.take`)."""
        self.store.take(source, reading, now, stamp, clock)

    def stale(self, now: float, inputs: Inputs | None = None) -> str:
        """Why the inputs cannot be used at time ``now`` ('' if they can)."""
        return self.store.stale(now, inputs)

    # -- the solve's -----------------------------------------------------------------------

    def grasp_at(self, inputs: Inputs, jacobians: bool = False
                 ) -> tuple[GraspSetup, np.ndarray | None]:
        """Return the grasp of a snapshot of inputs, and g(q) (:meth:`Cycle.grasp_at`)."""
        return self.solving.grasp_at(inputs, jacobians)

    def budget(self) -> float:
        """Return the time a cycle's solvers may take [s] (:meth:`Cycle.budget`)."""
        return self.solving.budget()

    def solve_inputs(self, inputs: Inputs, deadline: float | None = None
                     ) -> tuple[Solution, GraspMaps, np.ndarray | None]:
        """Solve the grasp of a snapshot of inputs, certified (:meth:`Cycle.solve_inputs`)."""
        return self.solving.solve_inputs(inputs, deadline)

    def gate(self, solution: Solution, g: np.ndarray | None) -> tuple[np.ndarray | None, str]:
        """Check a command last before it leaves (:meth:`Cycle.gate`)."""
        return self.solving.gate(solution, g)

    # -- the cycle: the parts together ----------------------------------------------------

    def cycle(self, now: float) -> CycleResult:
        """
        One cycle on the latest inputs (run it on each new joint state).

        Never raises: every failure is a fault, handled by the policy. The
        solvers stop by :meth:`budget`. A certified command from a cycle that
        took longer than ``cycle_budget`` is not published (it answers a joint
        state older than the budget), nor one whose inputs went stale while it
        was computed (checked at ``now`` plus the cycle's time).
        """
        t0 = time.perf_counter()
        # The parts' own config and counters: the controller's attributes are descriptors,
        # a Python call each, and this runs on every joint state.
        policy = self.policy
        config, counters = policy.config, policy.counters
        counters.cycles += 1
        result = self._attempt(now, None if self.untimed else t0 + self.solving.budget())
        elapsed = time.perf_counter() - t0
        counters.max_cycle_time = max(counters.max_cycle_time, elapsed)
        budget = config.cycle_budget
        judged = 0.0 if self.untimed else elapsed  # simulated time: the wall decides nothing
        if judged > budget:
            counters.overruns += 1
            if result.kind == 'solution':
                result = policy.faulted(now, f'cycle overrun ({1e3 * elapsed:.1f} ms > '
                                        f'cycle_budget {1e3 * budget:.1f} ms)',
                                        result.solution, result.maps, result.gravity_torque)
        late = self.store.stale(now + judged) if result.kind == 'solution' else ''
        if late:
            result = policy.faulted(now + judged, f'inputs went stale during the cycle: {late}',
                                    result.solution, result.maps, result.gravity_torque)
        if result.kind == 'solution':
            self._slew(result, now)
            why = policy.converted(result)
            if why:  # the command interface refuses it: a fault, never a clip
                result = policy.faulted(now, why, result.solution, result.maps,
                                        result.gravity_torque)
        if result.kind == 'solution':
            fallback = self.solving.fallback
            policy.committed(result, now, fallback is not None
                             and result.solution.backend == fallback.name)
            if config.tactile_source != 'none':
                self.solving.tactile = report = self.tactile_of(result, now)
                if report is not None and config.object_loop and config.loop_squeeze:
                    # The squeeze follows the touch sensors' usage while it is fresh and
                    # whole (every contact read), else the slip evidence.
                    self.solving.object_loop.squeeze.measured(report.usage, now, 'tactile')
        result.cycle_time = elapsed
        return result

    def tactile_of(self, result: CycleResult, now: float) -> TactileReport | None:
        """
        Compare a certified command's contact wrenches with the tactile readings at ``now``.

        The command's own wrenches (a rate-rule step's when it was one), at the contacts
        it was solved for; the wrench form's forces are projected on each contact's inward
        normal in its link's axes, at the command's configuration.
        """
        if result.kind != 'solution' or result.maps is None:
            return None
        maps = result.maps
        w = result.wrenches if result.wrenches is not None else result.solution.wrenches
        normals = None
        if self.config.tactile_source == 'wrench' and result.q is not None:
            placement = placements_at(self.setup.hand, result.q)
            normals = np.array([placement(link).rotation.T @ R[:, 2]
                                for link, R in zip(maps.links, maps.rotations)])
        return tactile_report(w, maps.links, self.inputs.tactile, normals, now,
                              self.config, self.setup.friction.mu1)

    def _slew(self, result: CycleResult, now: float) -> None:
        """
        Cut a certified command's step from the command in force to ``max_torque_rate``.

        The rate rule (docs/node.md): the command moves along the straight line from the
        command in force towards the certified command, no joint by more than
        ``max_torque_rate`` times the time since the command in force, and never more than
        that rate times ``command_period`` (a long gap gives no bigger step). With gravity
        compensation the contact torques are stepped and g(q) of the joint state it
        answers is taken whole: from zero torques the step starts at g(q), its contact
        wrenches ``s`` times the certified ones; from a command whose g(q) was another
        configuration's (or gravity's), that g is replaced by today's, else a step would
        carry ``(1 - s)`` times their difference into the contact wrenches; no joint
        moves more than the rate allows, so a g(q) that changed by more than that (the
        first gravity message, one after the IMU went stale) is blended as before.
        Across a change of the contact set, a contact that left fades out and a new one fades in
        (:func:`~.rates.step_wrenches`). The step's contact wrenches must lie in the exact
        cone, finite, with the step within the torque limits: else, or when they are not
        known, the certified command is published whole (``slew_refused``).
        """
        policy = self.policy
        config = policy.config
        if policy.in_force is None or policy.in_force_time is None:
            return
        gap = min(max(now - policy.in_force_time, 0.0), config.command_period)
        known, start, shift = policy.in_force_wrenches, policy.in_force, None
        g, g_in_force = result.gravity_torque, policy.in_force_gravity
        from_zero = known is not None and known.size == 0 and g is not None
        if from_zero:
            start = g  # zero torques: g(q) whole, the wrenches stepped
        most = config.max_torque_rate * gap
        if within_step(start, result.command, most):
            return  # the usual cycle: no joint moves more than a step (slewed gives None)
        if not from_zero and g is not None and g_in_force is not None \
                and g_in_force.shape == start.shape:
            shift = g - g_in_force  # the contact torques in force under today's g(q)
        if shift is not None and float(np.abs(shift).max()) > most:
            shift = None  # g(q) moved more than a step: the whole commands are blended
        limits = self.setup.hand.torque_limits
        step = slewed(start, result.command, most, limits, shift)
        if step is None:
            return
        cmd, s = step
        target = getattr(result.solution, 'wrenches', None)
        links = tuple(result.maps.links) if result.maps is not None else (
            () if target is not None and target.size == 0 else None)  # no contacts
        blend = step_wrenches(known, policy.in_force_links, target, links, s)
        friction = self.setup.friction
        if (blend is None or not np.all(np.isfinite(cmd))
                or not np.all(np.abs(cmd) <= limits)
                or float(cone_margin(np.vstack((blend[0], blend[2])), friction.mu1,
                                     friction.mu2).min()) < -STEP_CONE_TOLERANCE):
            self.counters.slew_refused += 1
            return
        result.command, result.wrenches = cmd, blend[0]
        result.faded = blend[1], blend[2]
        self.counters.slew_limited += 1

    def _attempt(self, now: float, deadline: float | None) -> CycleResult:
        """Solve and gate; a certified command is returned, not yet committed."""
        store = self.store
        reason = store.stale(now)
        if reason:
            return self.policy.faulted(now, reason)
        result = self.solving.attempt(store.inputs, deadline)
        if result.kind != 'solution':
            return self.policy.faulted(now, result.fault, result.solution, result.maps,
                                       result.gravity_torque)
        return result

    def watchdog(self, now: float) -> CycleResult | None:
        """
        Between cycles: notice stale joint states and apply the policy.

        Returns:
            A result when there is a fault (its command may be the zero policy's),
            None when the inputs are fresh or no joint state has arrived yet.
        """
        if self.inputs.q is None:
            return None  # not started: nothing was ever commanded
        reason = self.stale(now)
        return self.policy.faulted(now, reason) if reason else None

    def reconfigured(self, now: float) -> CycleResult | None:
        """
        After a parameter change: make the command in force valid at once.

        The rule (docs/node.md, "Faults"): the cycle runs again at once on the
        latest inputs with the new parameters, and a certified command is
        returned for publishing. If none comes out (stale inputs, an
        unholdable grasp, a failed solve) and the command in force exceeds the
        new torque limits, zero torques are returned, whatever
        ``fault_policy`` says: the effort controller would otherwise hold a
        torque the user has just forbidden. Otherwise the usual fault path
        applies (hold, then the policy).

        Returns:
            The result to publish, or None (nothing was ever commanded, or
            nothing to publish now).
        """
        if self.in_force is None:
            return None
        result = None
        if self.inputs.q is not None and not self.stale(now):
            result = self.cycle(now)
            if result.kind == 'solution':
                return result
        return self.policy.reconfigured(result, self.stale(now) if result is None else '')
