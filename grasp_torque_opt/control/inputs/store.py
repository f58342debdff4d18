# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The input store: the latest valid inputs, the header stamp rule, the rejections.

Every message is taken through one path, :meth:`InputStore.take`: its input's check
(:mod:`grasp_torque_opt.control.inputs`, one module each), then the header stamp rule;
a rejected message changes nothing but its counter (``Counters.rejected``) and
``last_rejection`` (docs/node.md, "Faults" and "Input checks").
"""

from __future__ import annotations

from dataclasses import dataclass, field
import math
from typing import Any

from grasp_torque_opt.control.geometry import ObjectPose
from grasp_torque_opt.control.inputs.contacts import ContactPoses
from grasp_torque_opt.control.inputs.registry import REGISTRY, SOURCES
from grasp_torque_opt.control.motion import ImuTracker, Motion
from grasp_torque_opt.control.parameters.generated import CycleConfig
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.link_surfaces import LinkSurfaces
from grasp_torque_opt.core.object_from_hand import ObjectFromHand
from grasp_torque_opt.core.scenario import ObjectSpec
import numpy as np
import pinocchio as pin


@dataclass(frozen=True)
class Inputs:
    """
    A snapshot of the latest valid inputs and their monotonic receipt times [s].

    ``contacts`` and ``wrench`` are None until one arrives (then the scenario's
    defaults are used); ``q`` is None until the first joint state. ``wrench`` is
    (frame, [F, M]) in that frame's axes. ``gravity`` is in base axes [m/s^2], None
    until one arrives (then ``CycleConfig.gravity`` and the scenario's load are used).
    ``motion`` is the IMU's (:class:`~grasp_torque_opt.control.motion.Motion`, used while
    fresh), ``effort`` the actuators' measured torques of the joint state (only with
    ``effort_estimation``; None when the driver reports none). ``object_pose`` is the
    object's frame (:class:`~grasp_torque_opt.control.geometry.ObjectPose`), None until
    one arrives (then the scenario's pose, fixed in the base frame). ``tactile`` is each
    sensing link's latest reading (:class:`~grasp_torque_opt.control.inputs.tactile.Touch`,
    with its own receipt time), None until one arrives; ``tactile_time`` the latest's.
    """

    q: np.ndarray | None = None
    q_time: float | None = None
    contacts: ContactPoses | None = None
    contacts_time: float | None = None
    wrench: tuple[str, np.ndarray] | None = None
    wrench_time: float | None = None
    gravity: np.ndarray | None = None
    gravity_time: float | None = None
    motion: Motion | None = None
    motion_time: float | None = None
    effort: np.ndarray | None = None
    effort_why: str = ''
    object_pose: ObjectPose | None = None
    object_pose_time: float | None = None
    tactile: dict | None = None
    tactile_time: float | None = None


@dataclass
class Counters:
    """
    Running totals, for diagnostics.

    ``solver_failures`` counts solves that raised or gave nothing certifiable
    (not the confirmed infeasible ones); ``fallback_solves`` certified
    solutions that came from the fallback backend after the first one failed;
    ``overruns`` cycles over ``cycle_budget``; ``max_cycle_time`` is the longest
    cycle [s]; ``slew_limited`` commands cut to ``max_torque_rate``; ``slew_refused``
    certified commands published whole because a step's contact wrenches were not known
    or not in the exact cone; ``rejected`` the rejected messages by source.
    """

    cycles: int = 0
    commands: int = 0
    zero_commands: int = 0
    faults: int = 0
    recoveries: int = 0
    overruns: int = 0
    solver_failures: int = 0
    fallback_solves: int = 0
    max_cycle_time: float = 0.0
    slew_limited: int = 0
    slew_refused: int = 0
    rejected: dict[str, int] = field(default_factory=lambda: dict.fromkeys(SOURCES, 0))


def replaced(obj, **changes):
    """
    Return ``dataclasses.replace(obj, **changes)`` for a dataclass without ``__post_init__``.

    It copies the fields instead of calling ``__init__``: a fifth of the time, twice in
    every cycle (the inputs, the grasp).
    """
    new = object.__new__(type(obj))
    new.__dict__.update(obj.__dict__)
    new.__dict__.update(changes)
    return new


class InputStore:
    """
    The latest valid inputs of the cycle, each checked whole before it is kept.

    Args:
        setup: the grasp (its hand's model and joints, its contacts, its q before
            the first joint state).
        config: the limits and timeouts the checks apply.
        counters: where rejections are counted (shared with the other parts).
    """

    def __init__(self, setup: GraspSetup, config: CycleConfig, counters: Counters) -> None:
        self.setup, self.config, self.counters = setup, config, counters
        self.inputs = Inputs()
        self.last_rejection = ''
        self._stamps: dict[str, tuple[float, float]] = {}  # input -> (stamp, receipt time)
        model = setup.hand.model
        #: Model joint name -> its index in q; and back.
        self.model_joints = {model.names[j]: model.joints[j].idx_q
                             for j in range(1, model.njoints) if model.joints[j].nq == 1}
        self.q_names = {i: n for n, i in self.model_joints.items()}
        #: (config, URDF lower and upper limits widened by joint_limit_tolerance).
        self._limits: tuple[CycleConfig, np.ndarray, np.ndarray] | None = None
        self.object: ObjectSpec | None = None  #: the scenario's object (the inward rule)
        #: The links' collision shapes contacts are checked on (None: the frame rule).
        self.surfaces: LinkSurfaces | None = None
        #: Where the fingertips place the object (None: no object; a pose is not compared).
        self.hand_object: ObjectFromHand | None = None
        #: The scenario's object pose in the base frame (None: no object; a pose is refused).
        self.scenario_pose: pin.SE3 | None = None
        #: The last accepted joint state's names, which of its entries are model joints,
        #: their indices in q, and the commanded joints it was checked against (a state
        #: with the same names skips the name checks).
        self.joint_names: tuple | None = None
        #: The bounds of that layout's used positions (joint_states.used_bounds' cache).
        self.joint_bounds: tuple | None = None
        self.imu = ImuTracker()
        #: The receipt time of the message being taken [s] (a check comparing it with the
        #: input's earlier messages reads it).
        self.now = 0.0
        #: Why the last joint state's efforts were not used ('' when they were).
        self.effort_missing = ''
        self.effort_index: tuple | None = None  # (names, indices of the actuators)

    def check_bytes(self, source: str, n: int) -> None:
        """
        Reject a message by the length of its serialized form, before it is deserialized.

        5.6 MB of poses took 0.8 s to deserialize here, holding up the loop.

        Raises:
            InputError: more than ``max_message_bytes`` (counted as a rejection).
        """
        limit = self.config.max_message_bytes
        if n > limit:
            e = InputError(source, f'{n} bytes serialized, more than max_message_bytes ({limit})')
            self.reject(source, e)
            raise e

    def check_size(self, source: str, n: int, frame_id: str = '') -> None:
        """
        Reject a message by its size alone, before it is read (inputs with a ``size`` rule).

        Raises:
            InputError: the size is out of bounds (counted as a rejection).
        """
        size = getattr(REGISTRY[source], 'size', None)
        if size is None:
            return
        try:
            size(self, n, frame_id)
        except InputError as e:
            self.reject(source, e)
            raise

    def take(self, source: str, reading: Any, now: float, stamp: float = 0.0,
             clock: float | None = None) -> None:
        """
        Take a message of the input ``source`` (its reading: plain data), or reject it.

        Args:
            source: the input's name (:data:`~.registry.REGISTRY`).
            reading: what its check takes (e.g. a
                :class:`~.joint_states.JointStateReading`).
            now: monotonic receipt time [s].
            stamp: header stamp [s] (0: unstamped).
            clock: the clock the stamps are on, now [s] (None: not checked ahead).

        Raises:
            InputError: the input's check or the stamp rule refused it (counted, the
                reason kept); nothing is kept.
        """
        given = REGISTRY[source]
        self.now = now
        try:
            value = given.check(self, reading)
            self._check_stamp(source, stamp, clock, now)
        except InputError as e:
            self.reject(source, e)
            raise
        self._keep_stamp(source, stamp, now, clock)
        self.inputs = replaced(self.inputs, **given.keep(self, value, now))

    def position_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Return the URDF's position limits widened by joint_limit_tolerance (cached)."""
        limits = self._limits
        if limits is None or limits[0] is not self.config:
            model, tol = self.setup.hand.model, self.config.joint_limit_tolerance
            limits = self._limits = (self.config, model.lowerPositionLimit - tol,
                                     model.upperPositionLimit + tol)
        return limits[1], limits[2]

    def reject(self, source: str, error: InputError) -> None:
        """Count a rejected message of ``source`` and keep its reason."""
        self.counters.rejected[source] = self.counters.rejected.get(source, 0) + 1
        self.last_rejection = str(error)  # names the field, e.g. contacts.poses[0]...

    def stale(self, now: float, inputs: Inputs | None = None) -> str:
        """Why the inputs cannot be used at time ``now`` ('' if they can)."""
        i = inputs or self.inputs
        free = not self.config.hold_object  # the grasp's inputs do not matter
        for given in REGISTRY.values():
            if free and getattr(given, 'grasp_only', False):
                continue
            why = given.stale(i, self.config, now)
            if why:
                return why
        return ''

    def _check_stamp(self, source: str, stamp: float, clock: float | None, now: float) -> None:
        """
        Apply the header stamp rule (docs/node.md, "Input checks").

        0 is an unstamped message: accepted, not compared. A stamp more than
        ``stamp_future_tolerance`` ahead of ``clock`` (when the clock runs, > 0)
        is rejected. A stamp before the input's mark is rejected (out of order),
        unless the mark is itself stale by receipt time: a restarted publisher
        or a rewound clock recovers after the input's timeout. The mark is the
        last accepted stamp, but never later than the clock when that message
        was accepted (:meth:`_keep_stamp`): a source stamping ahead of the clock,
        by a fast clock or a lie, cannot push it into the future and lock out a
        source whose stamps agree with the clock.
        """
        if stamp == 0.0:
            return
        if not math.isfinite(stamp) or stamp < 0.0:
            raise InputError(f'{source}.header.stamp', f'is negative ({stamp:.9g} s)')
        tol = self.config.stamp_future_tolerance
        if clock is not None and clock > 0.0 and stamp > clock + tol:
            raise InputError(f'{source}.header.stamp', f'is {stamp - clock:.3f} s ahead of the '
                             f'clock (stamp_future_tolerance {tol} s)')
        last = self._stamps.get(source)
        if last is not None and stamp < last[0] and now - last[1] <= self._timeout(source):
            raise InputError(f'{source}.header.stamp', f'goes backwards by '
                             f'{last[0] - stamp:.6f} s (out of order)')

    def _timeout(self, source: str) -> float:
        """Return how long an input's stamp mark holds [s] (no timeout: joint_state_timeout)."""
        t = REGISTRY[source].stamp_timeout(self.config)
        return t if t > 0 else self.config.joint_state_timeout

    def _keep_stamp(self, source: str, stamp: float, now: float, clock: float | None) -> None:
        """Mark an accepted stamp, never later than the clock (:meth:`_check_stamp`)."""
        if stamp != 0.0:
            mark = min(stamp, clock) if clock is not None and clock > 0.0 else stamp
            self._stamps[source] = (mark, now)
