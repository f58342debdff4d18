# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The cycle's solve: the grasp of the inputs, the compiled or the Python path, the gate.

A solve is certified (:func:`grasp_torque_opt.methods.dispatch.solve`, or the
compiled cycle of :mod:`grasp_torque_opt.control.compiled` where it applies, which
hands back what it cannot certify). The solvers are given a deadline that they keep
themselves (:meth:`Cycle.budget`); :meth:`Cycle.attempt` never raises: every failure
is a fault reason for the fault policy.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

from grasp_torque_opt.backends.base import Backend
from grasp_torque_opt.backends.daqp import DaqpSettings
from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings
from grasp_torque_opt.backends.registry import is_backend, settings_for
from grasp_torque_opt.control import compiled
from grasp_torque_opt.control.effort_load import Agreement, applied_torque, EffortLoad
from grasp_torque_opt.control.fault_policy import CycleResult
from grasp_torque_opt.control.geometry import geometry_of
from grasp_torque_opt.control.inputs.store import Counters, Inputs, replaced
from grasp_torque_opt.control.motion import Motion
from grasp_torque_opt.control.named_contacts import topic_contacts
from grasp_torque_opt.control.object_loop import LIMIT_FRACTION, LoopGains, ObjectLoop
from grasp_torque_opt.control.parameters.generated import CycleConfig
from grasp_torque_opt.core.exceptions import GraspTorqueError, InputError
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.solution import OPTIMAL, Solution
from grasp_torque_opt.methods.adaptive import AdaptiveSettings, Refiner
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.native.loader import fast_cycle
import numpy as np
import pinocchio as pin


def round_settings(solver: Backend) -> DaqpSettings:
    """
    Return DAQP's settings for tau-qp-adaptive's rounds, from the cycle's backend.

    The rounds solve with DAQP whatever the backend: ProxSuite's ``eps_abs`` and
    ``max_iter`` map to DAQP's as :func:`~grasp_torque_opt.backends.registry.settings_for`
    maps them, DAQP's are its own; quadprog and a solver of the caller's own have none
    (DAQP's defaults).
    """
    settings = solver.settings if is_backend(solver) else None
    if isinstance(settings, (ProxSuiteSettings, DaqpSettings)):
        return settings_for('daqp', settings)
    return DaqpSettings()


class Cycle:
    """
    Solve the grasp of a snapshot of inputs, certified, and gate its command.

    Args:
        setup: the grasp of the scenario. Its hand's Pinocchio data is used here.
        config: the method, tolerance, gravity and budget settings.
        counters: where solver failures are counted (shared).
        solver: the first backend.
        fallback: a second backend, asked in the same cycle when the first gives
            nothing certifiable; None for none.
    """

    def __init__(self, setup: GraspSetup, config: CycleConfig, counters: Counters,
                 solver: Backend, fallback: Backend | None = None) -> None:
        self.setup, self.config, self.counters = setup, config, counters
        self.solver, self.fallback = solver, fallback
        self.refiner: Refiner | None = None  # tau-qp-adaptive's, made when first used
        #: The scenario's load for a gravity input [m/s^2] (the object's weight moves with
        #: it), or None: the load does not depend on gravity.
        self.load_of_gravity = None
        #: The scenario's weight [N] (None: no object or no gravity): the effort
        #: estimation's bound, and whether it can run.
        self.weight: float | None = None
        #: The load estimated from efforts and its correction (:mod:`.effort_load`);
        #: ``estimating``: this cycle updates it (the loop's; the service's reads it).
        self.effort_load = EffortLoad()
        self.estimating = True
        #: The last command the gate passed has a joint at ``LIMIT_FRACTION`` of its limit.
        self.at_limit = False
        #: The object loop (:mod:`.object_loop`): the restoring wrench and the squeeze,
        #: moved by the loop's cycles (``estimating``), read by the service's.
        self.object_loop = ObjectLoop()
        self._gains: tuple[CycleConfig, LoopGains] | None = None  # the loop's, of a config
        self._gravity_in_use = np.zeros(3)  # base axes, of the last grasp_at
        #: Why the IMU is not used, at the last cycle ('' while it is, or none came).
        self.imu_state = ''
        #: The load planned at the last cycle, about the origin, base axes (None: none yet).
        self.load: np.ndarray | None = None
        #: Contacts from geometry (None: the scenario's), the object and its pose (.geometry).
        self.tracker = self.object = self.scenario_pose = None
        #: The object's frame in the base frame at the last cycle (None: no object).
        self.pose_in_use = None
        #: The links' collision shapes the contacts topic's points are checked on (None:
        #: none read; the frame rule, ``max_contact_link_distance``).
        self.surfaces = None
        #: Where the fingertips place the object
        #: (:class:`~grasp_torque_opt.core.object_from_hand.ObjectFromHand`; None: no object).
        self.hand_object = None
        #: The compiled cycle in use (None: the Python cycle), and why not when None.
        self.compiled_cycle: compiled.CompiledCycle | None = None
        self.compiled_reason = ''
        #: The links of the contacts topic's set at the last cycle that used it, and how
        #: many times that set changed (the first set is not a change).
        self.topic_links: tuple[str, ...] | None = None
        self.topic_changes = 0
        #: The last certified command's contacts against the tactile readings (None: none).
        self.tactile = None

    def grasp_at(self, inputs: Inputs, jacobians: bool = False
                 ) -> tuple[GraspSetup, np.ndarray | None]:
        """
        Return the grasp of a snapshot of inputs, and g(q) if compensated.

        With ``jacobians``, the joint Jacobians are computed with the placements (the
        compiled cycle reads both from the hand's Pinocchio data).

        Raises:
            InputError: a contact point beyond ``max_contact_distance`` or off its
                link's surface or the object's, a normal pointing away from the object
                origin (at this configuration), or the contacts cannot be placed on their
                links.
        """
        setup = self.setup
        hand = setup.hand
        q = inputs.q
        if hand.coupling.mimics:
            # Coupled joints follow their actuators, whatever a joint state says of them.
            q = hand.complete(q.copy())
        model, data = hand.model, hand.data
        if jacobians:
            pin.computeJointJacobians(model, data, q)
            pin.updateFramePlacements(model, data)
        else:
            pin.framesForwardKinematics(model, data, q)
        contacts, origin, at = geometry_of(self, inputs, q)
        if inputs.contacts is not None:  # the topic's, on its links (named or by index)
            contacts = topic_contacts(self, inputs.contacts, origin)
        motion = self.motion_in_use(inputs)
        wrench = setup.external_wrench
        if inputs.wrench is not None:
            frame, w = inputs.wrench
            R = data.oMf[model.getFrameId(frame or hand.base_frame)].rotation
            if hand.base_link is not None:
                R = data.oMf[model.getFrameId(hand.base_link)].rotation.T @ R
            wrench = np.concatenate((R @ w[:3], R @ w[3:]))
        elif self.load_of_gravity is not None and any(
                x is not None for x in (motion, inputs.gravity, at)):
            wrench = self.load_of_gravity(motion.gravity if motion is not None else
                                          self.config.gravity if inputs.gravity is None
                                          else inputs.gravity, motion, at)
        estimating = self.config.effort_estimation and self.estimating
        g = None
        gravity = self._gravity_in_use = np.asarray(
            motion.gravity if motion is not None else self.config.gravity
            if inputs.gravity is None else inputs.gravity, dtype=float)
        if self.config.gravity_compensation or estimating:
            if hand.base_link is not None:  # given in the base link's axes; Pinocchio's: root
                gravity = data.oMf[model.getFrameId(hand.base_link)].rotation @ gravity
            model.gravity.linear = gravity
            g = hand.actuator_torques(pin.computeGeneralizedGravity(model, data, q))
        if self.config.effort_estimation:
            at_q = replaced(setup, q=q, contacts=contacts, object_origin=origin)
            wrench = wrench + self._correction(at_q, g, inputs, wrench, estimating)
        elif self.estimating and self.effort_load.estimate is not None:
            self.effort_load.reset()  # turned off: turned on again, it starts anew
        if not self.config.gravity_compensation:
            g = None
        friction = setup.friction
        if self.config.object_loop:
            restoring, friction = self._object_loop(q, contacts, origin, inputs.q_time)
            wrench = wrench - restoring  # the hand adds w_r: G f = -(w_ext - w_r)
        elif self.estimating and self.object_loop.tracker is not None:
            self.object_loop = ObjectLoop()  # turned off: turned on again, it settles anew
        self.load = wrench
        return replaced(setup, q=q, contacts=contacts, external_wrench=wrench,
                        torque_offset=g, object_origin=origin, friction=friction), g

    def _object_loop(self, q: np.ndarray, contacts: list, origin: np.ndarray, now: float
                     ) -> tuple[np.ndarray, Any]:
        """Return the object loop's restoring wrench and the squeezed friction."""
        loop, friction = self.object_loop, self.setup.friction
        if self.estimating:
            made = self._gains
            if made is None or made[0] is not self.config:  # a parameter change: new config
                self._gains = made = (self.config, loop_gains(self.config))
            gains = made[1]
            gap = self.config.joint_state_timeout
            loop.update(self.setup.hand, contacts, q, now, origin, self.weight, gains, gap)
            if gains.squeeze:
                slip = loop.slip / gains.slip_residual
                loop.squeeze.update(friction.min_normal_force, slip, now, gains,
                                    loop.previous, gap)
            else:
                loop.squeeze.reset()
        return loop.wrench, self.squeezed()

    def squeezed(self) -> Any:
        """Return the grasp's friction with the squeeze's minimum normal force (if any)."""
        friction, force = self.setup.friction, self.object_loop.squeeze.normal_force
        if not self.config.object_loop or force is None or force == friction.min_normal_force:
            return friction
        return dataclasses.replace(friction, min_normal_force=force)

    def motion_in_use(self, inputs: Inputs) -> Motion | None:
        """
        Return the IMU's motion if it is fresh at the joint state's receipt, else None.

        Fresh: received no more than its timeout (a few of its periods, ``imu.*``) before
        the joint state. Else the scenario's (or the gravity topic's) gravity is used, and
        :attr:`imu_state` says why.
        """
        motion = inputs.motion
        if motion is None:
            return None
        age = inputs.q_time - inputs.motion_time
        if age > motion.timeout:
            self.imu_state = (f'imu stale ({age:.4f} s > {motion.timeout:.4f} s): the '
                              "scenario's gravity is used")
            return None
        self.imu_state = ''
        return motion

    def _correction(self, at: GraspSetup, g: np.ndarray | None, inputs: Inputs,
                    model: np.ndarray, estimating: bool) -> np.ndarray:
        """Return the effort estimation's correction (:mod:`.effort_load`; loop's updates)."""
        est = self.effort_load
        if not estimating:
            return est.correction
        if self.weight is None:
            est.turn_off("effort_estimation needs the scenario's object and gravity (its "
                         'weight bounds the correction)')
            return est.correction
        if inputs.effort is None:
            est.turn_off('effort_estimation off: ' + (inputs.effort_why or 'no effort'))
            return est.correction
        c = self.config
        if c.effort_report == 'commanded' and not c.effort_driver_stiffness > 0:
            est.turn_off('effort_estimation off: effort_report commanded needs '
                         'effort_estimation.driver_stiffness > 0')
            return est.correction
        est.off = ''
        maps = at.maps()
        bounds = est.bound(self.weight, c.effort_max_load_ratio, maps.positions,
                           at.object_origin)
        gravity = self._gravity_in_use if c.effort_mass_only else None
        nominal = float(np.linalg.norm(c.gravity))
        frozen = self._gate(at, maps.positions, inputs.q_time)
        q = at.q[at.hand.idx_q]
        reference = c.effort_driver_reference or self.setup.q[at.hand.idx_q]
        tau = applied_torque(inputs.effort, c.effort_report, c.effort_driver_stiffness,
                             reference, q)
        return est.update(est.measured(maps.G, maps.J, tau, g), model,
                          inputs.q_time, c.effort_filter, c.effort_time_constant, bounds,
                          gap=c.joint_state_timeout, gravity=gravity, frozen=frozen,
                          window=c.effort_speed_window,
                          unwind=est.agreement is not None and est.agreement.off_hold,
                          mass_bound=bounds[0] / nominal if nominal > 0 else 0.0,
                          nominal=nominal)

    def _gate(self, at: GraspSetup, positions: np.ndarray, now: float) -> str:
        """Return why the effort estimate is frozen ('' open; :class:`.effort_load.Agreement`)."""
        est, c = self.effort_load, self.config
        if self.hand_object is None:  # no object: no fingertips' estimate, no gate
            est.agreement = None
            return ''
        if est.agreement is None:
            est.agreement = Agreement()
        tips = self.hand_object.estimate(at.q)
        return est.agreement.check(tips, positions - at.object_origin, now,
                                   c.effort_speed_window, c.joint_state_timeout,
                                   (c.effort_max_object_speed, c.effort_max_residual))

    def budget(self) -> float:
        """
        Return the time a cycle's solvers may take [s].

        That is ``cycle_budget``, or ``joint_state_timeout`` if smaller (a command later
        than that would answer a stale joint state).
        """
        return min(self.config.cycle_budget, self.config.joint_state_timeout)

    def solve_inputs(self, inputs: Inputs, deadline: float | None = None
                     ) -> tuple[Solution, GraspMaps, np.ndarray | None]:
        """
        Solve the grasp of a snapshot of inputs with the tau-QP (certified).

        Args:
            inputs: the snapshot.
            deadline: ``time.perf_counter()`` value by which the solvers stop [s]
                (None: only their iteration caps).

        Raises:
            InputError: the inputs do not make a grasp (e.g. a tangent parallel to
                its normal).
        """
        # The compiled cycle is made for the squeeze's friction (:meth:`squeezed`); made
        # again when this cycle's grasp moved it.
        friction = self.squeezed()
        fast = self._compiled(self.setup if friction is self.setup.friction else
                              replaced(self.setup, friction=friction))
        # The joint Jacobians for the compiled call, unless it computes its kinematics.
        jacobians = fast is not None and fast.tree is None
        setup, g = self.grasp_at(inputs, jacobians=jacobians)
        if fast is not None and setup.friction is not self.setup.friction:
            fast = self._compiled(setup)
        solver, fallback, handed_back = self.solver, self.fallback, ''
        if fast is not None:
            sol, maps = fast.solve(setup, None if deadline is None else
                                   deadline - time.perf_counter(), kinematics=not jacobians)
            if sol is not None:
                return sol, maps, g
            handed_back = maps
            if fast.last_code in compiled.SOLVER_CODES and fallback is not None:
                # ProxSuite was tried, warm and cold: the fallback answers, with the rest of
                # the time (the Python cycle would ask ProxSuite again first).
                solver, fallback = fallback, None
        maps = setup.maps()
        sol = solve(setup, self.config.method, maps=maps, solver=solver,
                    fallback=fallback, tolerance=self.config.certificate_tolerance,
                    refiner=self._refiner(), deadline=deadline)
        if handed_back:
            sol.message = f'{sol.message}; after the {handed_back}'
        return sol, maps, g

    def _compiled(self, setup: GraspSetup) -> compiled.CompiledCycle | None:
        """Return the compiled cycle for this grasp and solver, or None (the reason kept)."""
        if not self.config.compiled:
            # Dropped, not kept aside: turned on again, it starts anew (cold).
            self.compiled_cycle, self.compiled_reason = None, 'off (compiled: false)'
            return None
        fast, tol = self.compiled_cycle, self.config.certificate_tolerance
        if fast is not None and fast.fits(setup, self.solver, tol):
            if fast.gave_up:
                self.compiled_reason = fast.gave_up
                return None
            return fast
        why = compiled.unsupported(setup, self.config.method, self.solver)
        self.compiled_reason = why
        self.compiled_cycle = None if why else compiled.CompiledCycle(
            setup, self.solver, tol, previous=fast)
        return self.compiled_cycle

    def _refiner(self) -> Refiner | None:
        """tau-qp-adaptive's rounds (kept across cycles, warm as the solver is), else None."""
        if self.config.method != 'tau-qp-adaptive':
            return None
        warm = self.solver.warm_start if is_backend(self.solver) else False
        daqp = round_settings(self.solver)
        wanted = AdaptiveSettings(warm_start=warm, eps_abs=daqp.primal_tol,
                                  max_iter=daqp.iter_limit)
        if self.refiner is None or self.refiner.settings != wanted:
            self.refiner = Refiner(wanted)
        return self.refiner

    def gate(self, solution: Solution, g: np.ndarray | None) -> tuple[np.ndarray | None, str]:
        """
        Check a command last before it leaves: certified, finite, sized, within limits.

        Also notes whether a joint of it is at :data:`~.object_loop.LIMIT_FRACTION` of its
        limit or beyond (:attr:`at_limit`, for the object loop's anti-windup).
        """
        if not solution.optimal:
            self.at_limit = False
            return None, f'no certified solution ({solution.status}: {solution.message})'
        lim = self.setup.hand.torque_limits
        cmd, worst, at_limit = checked_command(solution.tau, g, lim, LIMIT_FRACTION)
        self.at_limit = worst == -1 and at_limit
        if worst == -1:
            return cmd, ''
        if worst == SIZES_DIFFER:
            return None, f'command has {cmd.size} values for {lim.size} joints'
        if worst == NOT_FINITE:
            return None, 'command not finite'
        return None, f'command over the limit at {self.setup.hand.joints[worst]}'

    def gravity_torque(self, inputs: Inputs) -> np.ndarray:
        """
        Return g(q) at a snapshot's joints, under the gravity in use, actuator space [N m].

        The gravity in use is the fresh IMU's apparent gravity, else the gravity topic's,
        else the ``gravity`` parameter (as :meth:`grasp_at` takes it).
        """
        hand = self.setup.hand
        q = hand.complete(inputs.q.copy()) if hand.coupling.mimics else inputs.q
        model, data = hand.model, hand.data
        motion = self.motion_in_use(inputs)
        gravity = self._gravity_in_use = np.asarray(
            motion.gravity if motion is not None else self.config.gravity
            if inputs.gravity is None else inputs.gravity, dtype=float)
        if hand.base_link is not None:  # given in the base link's axes; Pinocchio's: root
            pin.framesForwardKinematics(model, data, q)
            gravity = data.oMf[model.getFrameId(hand.base_link)].rotation @ gravity
        model.gravity.linear = gravity
        return hand.actuator_torques(pin.computeGeneralizedGravity(model, data, q))

    def free_hand(self, inputs: Inputs) -> CycleResult:
        """
        Return the command with no object in the hand (``hold_object`` false): g(q) alone.

        No contact, no load, no QP: the solution is zero joint torques with no contact
        wrenches, and the command the fingers' own gravity torques (zeros without
        ``gravity_compensation``), gated as every command is (finite, sized, within the
        torque limits). Its empty wrenches let the rate rule fade the grasp's contacts
        out, and in again when ``hold_object`` is set back.
        """
        hand = self.setup.hand
        t0 = time.perf_counter()
        g = self.gravity_torque(inputs) if self.config.gravity_compensation else None
        self.load = None
        sol = Solution(status=OPTIMAL, method='gravity-only', joints=list(hand.joints),
                       tau=np.zeros(hand.m), wrenches=np.zeros((0, 4)),
                       message='hold_object false: no object, g(q) alone',
                       backend='none', friction_usage=np.zeros(0))
        sol.solve_time_s = time.perf_counter() - t0
        cmd, why = self.gate(sol, g)
        if cmd is None:
            return CycleResult(None, 'none', sol, None, g, why)
        return CycleResult(cmd, 'solution', sol, None, g, q=inputs.q)

    def attempt(self, inputs: Inputs, deadline: float | None) -> CycleResult:
        """
        Solve and gate; never raises.

        The object loop is told the outcome (its anti-windup, :meth:`ObjectLoop.after`).

        Returns:
            A certified command (kind ``solution``, not yet committed), or a result of
            kind ``none`` whose ``fault`` says why there is none.
        """
        result = self._attempt(inputs, deadline)
        if self.estimating and self.config.object_loop:  # off: a loop turned on settles anew
            certified = result.kind == 'solution'
            self.object_loop.after(certified, result.command, self.setup.hand.torque_limits,
                                   self.at_limit if certified else None)
        return result

    def _attempt(self, inputs: Inputs, deadline: float | None) -> CycleResult:
        """Solve and gate (:meth:`attempt`)."""
        try:
            if not self.config.hold_object:
                return self.free_hand(inputs)
            sol, maps, g = self.solve_inputs(inputs, deadline)
        except InputError as e:
            return CycleResult(None, 'none', fault=f'inputs do not make a grasp: {e}')
        except GraspTorqueError as e:
            self.counters.solver_failures += 1
            return CycleResult(None, 'none', fault=f'solver failed: {e}')
        except Exception as e:  # noqa: BLE001 -- a control loop fails safe, it does not die
            self.counters.solver_failures += 1
            return CycleResult(None, 'none', fault=f'cycle failed: {type(e).__name__}: {e}')
        if sol.status == 'failed':
            self.counters.solver_failures += 1
        cmd, why = self.gate(sol, g)
        if cmd is None:
            return CycleResult(None, 'none', sol, maps, g, why)
        return CycleResult(cmd, 'solution', sol, maps, g, q=inputs.q)


#: :func:`checked_command`'s ``worst`` for a command of the wrong size, or not finite.
SIZES_DIFFER, NOT_FINITE = -3, -2
_NO_OFFSET = np.zeros(0)


def checked_command(tau: np.ndarray, g: np.ndarray | None, limits: np.ndarray,
                    fraction: float) -> tuple[np.ndarray, int, bool]:
    """
    Return the command ``tau + g``, how it meets the limits, and whether it is at a limit.

    Returns:
        (the command; -1 when every joint is within its limit,
        :data:`NOT_FINITE` or :data:`SIZES_DIFFER`, else the joint farthest over its
        limit; whether a joint is at ``fraction`` of its limit or beyond). In one
        compiled call where the compiled module is built (the gate of every cycle: five
        numpy calls took 2 us), else :func:`checked_command_numpy`; the same answer.
    """
    if fast_cycle is not None and tau.shape == limits.shape and (
            g is None or g.shape == limits.shape):
        return fast_cycle.gate_command(tau, _NO_OFFSET if g is None else g, limits, fraction)
    return checked_command_numpy(tau, g, limits, fraction)


def checked_command_numpy(tau: np.ndarray, g: np.ndarray | None, limits: np.ndarray,
                          fraction: float) -> tuple[np.ndarray, int, bool]:
    """Give :func:`checked_command` in numpy."""
    cmd = tau + (0.0 if g is None else g)
    if cmd.shape != limits.shape:
        return cmd, SIZES_DIFFER, False
    size = np.abs(cmd)
    at_limit = bool((size >= fraction * limits).any())
    if (size <= limits).all():  # False for NaN as well
        return cmd, -1, at_limit
    if not np.all(np.isfinite(cmd)):
        return cmd, NOT_FINITE, at_limit
    if np.any(size > limits):
        return cmd, int(np.argmax(size - limits)), at_limit
    return cmd, -1, at_limit


def loop_gains(config: CycleConfig) -> LoopGains:
    """Return the object loop's settings from the cycle's (``object_loop.*``, ``squeeze.*``)."""
    return LoopGains(**{f.name: getattr(config, f'loop_{f.name}')
                        for f in dataclasses.fields(LoopGains)})
