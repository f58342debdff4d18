# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The input store: the latest valid inputs, the header stamp rule, the rejections.

Every message is checked whole (:mod:`grasp_torque_opt.control.checks`, then the
stamp rule) before it is kept; a rejected message changes nothing but its
counter (``Counters.rejected``) and ``last_rejection`` (docs/node.md, "Faults"
and "Input checks").
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from grasp_torque_opt.control.checks import (
    check_joint_limits,
    check_joint_names,
    checked_gravity,
    checked_wrench,
    contact_rotations,
    MAX_ABS_JOINT_POSITION,
)
from grasp_torque_opt.control.geometry import ObjectPose, ObjectPoseInput
from grasp_torque_opt.control.motion import checked_imu, efforts_of, ImuTracker, Motion
from grasp_torque_opt.control.named_contacts import named_frame, split_frame_id
from grasp_torque_opt.control.parameters import CycleConfig
from grasp_torque_opt.control.plausible import check_contacts
from grasp_torque_opt.control.rates import turned_towards
from grasp_torque_opt.control.stamps import StampRule
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.scenario import ObjectSpec
import numpy as np

#: The input topics, as named in counters, stamps and messages (and ``gravity``, counted
#: from its first rejection: it is optional).
SOURCES = ('joint_states', 'contacts', 'external_wrench')


@dataclass(frozen=True)
class ContactPoses:
    """
    Contact frames as estimated: pose i is contact i's frame in frame ``frame``.

    Attributes:
        frame: model frame the poses are expressed in ('' = the base frame).
        positions: contact points, shape (p, 3) [m].
        rotations: contact frame axes (columns x, y, z = inward normal), shape (p, 3, 3).
        links: the link of each pose, as named in the message (None: the scenario's
            contacts, by index).
    """

    frame: str
    positions: np.ndarray
    rotations: np.ndarray
    links: tuple[str, ...] | None = None


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
    one arrives (then the scenario's pose, fixed in the base frame).
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


def stamp_seconds(sec: int, nanosec: int) -> float:
    """Return a builtin_interfaces/Time as seconds (0.0 for an unstamped message)."""
    return sec + 1e-9 * nanosec


class InputStore(StampRule, ObjectPoseInput):
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
        self._stamps: dict[str, tuple[float, float]] = {}  # source -> (stamp, receipt time)
        model = setup.hand.model
        self._model_joints = {model.names[j]: model.joints[j].idx_q
                              for j in range(1, model.njoints) if model.joints[j].nq == 1}
        self._q_names = {i: n for n, i in self._model_joints.items()}
        #: (config, URDF lower and upper limits widened by joint_limit_tolerance).
        self._limits: tuple[CycleConfig, np.ndarray, np.ndarray] | None = None
        self.object: ObjectSpec | None = None  #: the scenario's object (the inward rule)
        #: The last accepted joint state's names, which of its entries are model joints,
        #: their indices in q, and the commanded joints it was checked against (a state
        #: with the same names skips the name checks).
        self._names: tuple | None = None
        self.imu = ImuTracker()
        #: Why the last joint state's efforts were not used ('' when they were).
        self.effort_missing = ''
        self._effort_index: tuple | None = None  # (names, indices of the actuators)

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
        Reject a message by its size alone, before it is read.

        Args:
            source: ``joint_states`` (``n`` names or positions, at most
                ``max_joint_state_entries``) or ``contacts`` (``n`` poses, one per link
                named in ``frame_id``, else per scenario contact: :mod:`.named_contacts`).

        Raises:
            InputError: the size is out of bounds (counted as a rejection).
        """
        try:
            if source == 'joint_states' and n > self.config.max_joint_state_entries:
                limit = self.config.max_joint_state_entries
                raise InputError('joint_states', f'{n} entries, more than '
                                 f'max_joint_state_entries ({limit})')
            if source == 'contacts':
                split_frame_id(frame_id, n, len(self.setup.contacts))
        except InputError as e:
            self.reject(source, e)
            raise

    def update_joint_state(self, names: list[str], positions: list[float], now: float,
                           stamp: float = 0.0, clock: float | None = None,
                           efforts: list[float] | None = None) -> None:
        """
        Take a joint state: names and positions, any order, extra joints ignored.

        Only the positions of model joints are used, so NaN elsewhere (velocity,
        effort, unknown joints) is accepted. Names that are not model joints are
        ignored (a robot's joint_states lists every joint), but must be unique.

        Args:
            names: joint names.
            positions: their positions [rad or m].
            now: monotonic receipt time [s].
            stamp: header stamp [s] (0: unstamped).
            clock: the clock the stamps are on, now [s] (None: not checked ahead).
            efforts: their measured efforts [N m], read only with ``effort_estimation``
                (empty or not finite: none, :attr:`effort_missing` says why; never a
                rejection).

        Raises:
            InputError: more than ``max_joint_state_entries`` entries, length
                mismatch, empty or duplicate name, a commanded joint missing, a
                used position not finite or beyond
                :data:`~grasp_torque_opt.control.checks.MAX_ABS_JOINT_POSITION`,
                a bad stamp. The state is not kept.
        """
        self.check_size('joint_states', max(len(names), len(positions)))
        q = (self.setup.q if self.inputs.q is None else self.inputs.q).copy()
        known, checked = self._names, None
        try:
            values = None
            if known is not None and known[3] is self.setup.hand.joints and \
                    len(positions) == len(names) and names == known[0]:
                # The same names as the last accepted state (a driver's every message):
                # their checks hold; one array comparison checks the positions (NaN fails
                # it, and then the loop below names the position).
                values = np.asarray(positions, dtype=float)[known[1]]
                if not (np.abs(values) <= MAX_ABS_JOINT_POSITION).all():
                    values = None
            if values is not None:
                q[known[2]] = values
            else:
                checked = check_joint_names(names, positions, q, self._model_joints,
                                            self.setup.hand.joints)
            self._check_limits(q, (checked or known)[2])
            self._check_stamp('joint_states', stamp, clock, now)
        except InputError as e:
            self.reject('joint_states', e)
            raise
        if checked is not None:
            self._names = checked
        self._keep_stamp('joint_states', stamp, now, clock)
        effort = None
        if self.config.effort_estimation:
            effort, self.effort_missing, self._effort_index = efforts_of(
                names, efforts, self.setup.hand.joints, self._effort_index)
        self.inputs = replaced(self.inputs, q=q, q_time=now, effort=effort,
                               effort_why=self.effort_missing)

    def _check_limits(self, q: np.ndarray, used: np.ndarray) -> None:
        """Refuse a used position beyond its URDF limits (:func:`.checks.check_joint_limits`)."""
        limits = self._limits
        if limits is None or limits[0] is not self.config:
            model, tol = self.setup.hand.model, self.config.joint_limit_tolerance
            limits = self._limits = (self.config, model.lowerPositionLimit - tol,
                                     model.upperPositionLimit + tol)
        check_joint_limits(q, used, limits[1], limits[2], self._q_names,
                           self.config.joint_limit_tolerance)

    def update_contacts(self, frame: str, positions: np.ndarray, quaternions: np.ndarray,
                        now: float, stamp: float = 0.0, clock: float | None = None) -> None:
        """
        Take contact frames: one pose per scenario contact, or per named link.

        Args:
            frame: model frame of the poses ('' = the base frame), or
                ``FRAME;LINK_1,...,LINK_n``: one pose per named link, in order
                (:mod:`.named_contacts`).
            positions: contact points, shape (p, 3) [m].
            quaternions: contact frame orientations (x, y, z, w), shape (p, 4).
            now: monotonic receipt time [s].
            stamp: header stamp [s] (0: unstamped).
            clock: the clock the stamps are on, now [s] (None: not checked ahead).

        Raises:
            InputError: wrong count or shape, unknown frame, a bad frame_id or named
                link (:func:`.named_contacts.named_frame`), non-finite values, a
                non-unit quaternion, an implausible contact at the latest joint state
                (:func:`.plausible.check_contacts`), a bad stamp. The contacts are not
                kept. (The cycle checks them again, where the frame is placed.)
        """
        positions = np.asarray(positions, dtype=float)
        quaternions = np.asarray(quaternions, dtype=float)
        try:
            frame, links = named_frame(self.setup, frame, len(positions))
            rotations = contact_rotations(self.setup.hand.model, len(positions), frame,
                                          positions, quaternions)
            q = self.setup.q if self.inputs.q is None else self.inputs.q  # the latest
            check_contacts(self.setup, self.object, q, frame, positions, rotations,
                           self.config.max_contact_link_distance, links)
            self._check_stamp('contacts', stamp, clock, now)
        except InputError as e:
            self.reject('contacts', e)
            raise
        self._keep_stamp('contacts', stamp, now, clock)
        self.inputs = dataclasses.replace(
            self.inputs, contacts=ContactPoses(frame, positions, rotations, links),
            contacts_time=now)

    def update_wrench(self, frame: str, force: np.ndarray, torque: np.ndarray,
                      now: float, stamp: float = 0.0, clock: float | None = None) -> None:
        """
        Take the load on the object (about its origin), axes of model frame ``frame``.

        Args:
            frame: model frame of the axes ('' = the base frame).
            force: force [N], shape (3,).
            torque: moment about the object origin [N m], shape (3,).
            now: monotonic receipt time [s].
            stamp: header stamp [s] (0: unstamped).
            clock: the clock the stamps are on, now [s] (None: not checked ahead).

        Raises:
            InputError: unknown frame, non-finite values, a force or moment norm
                above ``max_wrench_force`` / ``max_wrench_torque``, a bad stamp.
                The load is not kept.
        """
        try:
            w = checked_wrench(self.setup.hand.model, frame, force, torque,
                               self.config.max_wrench_force, self.config.max_wrench_torque)
            self._check_stamp('external_wrench', stamp, clock, now)
        except InputError as e:
            self.reject('external_wrench', e)
            raise
        self._keep_stamp('external_wrench', stamp, now, clock)
        # Kept in the given axes; turned into base axes at the cycle's configuration.
        self.inputs = dataclasses.replace(self.inputs, wrench=(frame, w), wrench_time=now)

    def update_gravity(self, frame: str, vector: np.ndarray, now: float, stamp: float = 0.0,
                       clock: float | None = None, rotation: np.ndarray | None = None,
                       unresolved: str = 'tf2_ros is not installed') -> None:
        """
        Take gravity [m/s^2]: g(q) and the scenario's load (its object's weight) follow it.

        Args:
            frame: the frame of the vector: '' or the base frame, or any frame when
                ``rotation`` is given.
            vector: gravity in ``frame`` [m/s^2], shape (3,).
            now: monotonic receipt time [s].
            stamp: header stamp [s] (0: unstamped).
            clock: the clock the stamps are on, now [s] (None: not checked ahead).
            rotation: base-from-frame rotation, shape (3, 3), when the caller could
                look ``frame`` up (tf2); None: ``frame`` must be the base frame.
            unresolved: why ``frame`` could not be looked up (for the message).

        Raises:
            InputError: another frame without ``rotation``, not finite, a norm above
                :data:`~grasp_torque_opt.control.checks.MAX_GRAVITY` or outside
                ``gravity_norm_bounds``, a bad stamp. The vector is not kept. Else the
                gravity in use turns towards it at ``max_gravity_rate`` (:mod:`.rates`).
        """
        try:
            g = checked_gravity(self.setup.hand.base_frame, frame, vector, rotation,
                                unresolved, self.config.gravity_norm_bounds)
            self._check_stamp('gravity', stamp, clock, now)
        except InputError as e:
            self.reject('gravity', e)
            raise
        self._keep_stamp('gravity', stamp, now, clock)
        old, timeout = self.inputs.gravity, self.config.gravity_timeout
        if old is not None and not (timeout > 0 and now - self.inputs.gravity_time > timeout):
            step = self.config.max_gravity_rate * (now - self.inputs.gravity_time)
            g = turned_towards(old, g, step)
        self.inputs = dataclasses.replace(self.inputs, gravity=g, gravity_time=now)

    def update_imu(self, frame: str, specific_force: np.ndarray, omega: np.ndarray,
                   now: float, stamp: float = 0.0, clock: float | None = None,
                   transform: tuple[np.ndarray, np.ndarray] | None = None,
                   unresolved: str = 'tf2_ros is not installed') -> None:
        """
        Take an IMU reading of the base (frame '' or the base, else ``transform``'s).

        ``specific_force`` [m/s^2] reads -g at rest; ``omega`` [rad/s]; ``transform``: the
        IMU frame's rotation and origin in the base frame; the rest as
        :meth:`update_gravity`'s. A reading :func:`.motion.checked_imu` refuses, or with a
        bad stamp, raises InputError and is not kept (the last one ages out; then the
        scenario's gravity is used again).
        """
        try:
            g, w, point = checked_imu(self.setup.hand.base_frame, frame, specific_force,
                                      omega, transform, unresolved, self.config)
            self._check_stamp('imu', stamp, clock, now)
        except InputError as e:
            self.reject('imu', e)
            raise
        self._keep_stamp('imu', stamp, now, clock)
        c = self.config
        alpha = self.imu.update(now, w, c.imu_angular_filter, c.imu_timeout_bounds[1])
        motion = Motion(g, w, alpha, point, self.imu.timeout(c.imu_timeout_periods,
                                                             c.imu_timeout_bounds))
        self.inputs = dataclasses.replace(self.inputs, motion=motion, motion_time=now)

    def reject(self, source: str, error: InputError) -> None:
        """Count a rejected message of ``source`` and keep its reason."""
        self.counters.rejected[source] = self.counters.rejected.get(source, 0) + 1
        self.last_rejection = str(error)  # names the field, e.g. contacts.poses[0]...

    def stale(self, now: float, inputs: Inputs | None = None) -> str:
        """Why the inputs cannot be used at time ``now`` ('' if they can)."""
        i = inputs or self.inputs
        c = self.config
        if i.q is None:
            return 'no joint state yet'
        if now - i.q_time > c.joint_state_timeout:
            return f'joint_states stale ({now - i.q_time:.3f} s > {c.joint_state_timeout} s)'
        if i.contacts_time is not None and c.contacts_timeout > 0 and \
                now - i.contacts_time > c.contacts_timeout:
            return f'contacts stale ({now - i.contacts_time:.3f} s > {c.contacts_timeout} s)'
        if i.wrench_time is not None and c.wrench_timeout > 0 and \
                now - i.wrench_time > c.wrench_timeout:
            return f'external_wrench stale ({now - i.wrench_time:.3f} s > {c.wrench_timeout} s)'
        if i.object_pose_time is not None and 0 < c.object_pose_timeout < now - i.object_pose_time:
            return f'object_pose stale (older than object_pose.timeout, {c.object_pose_timeout} s)'
        if i.gravity_time is not None and c.gravity_timeout > 0 and \
                now - i.gravity_time > c.gravity_timeout:
            return f'gravity stale ({now - i.gravity_time:.3f} s > {c.gravity_timeout} s)'
        return ''
