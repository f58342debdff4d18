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
command leaves, not only when the cycle starts.

Input rules (docs/node.md, "Faults" and "Input checks"): every message is checked
whole before it is kept (sizes, names, finite values, unit quaternions, known
frames, magnitudes, header stamps); a rejected message changes nothing.
"""

from __future__ import annotations

from collections import Counter
import dataclasses
from dataclasses import dataclass, field
import math
import time

from grasp_torque_opt.backends import make_solver
from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings
from grasp_torque_opt.control import compiled
from grasp_torque_opt.core.certificate import DEFAULT_TOLERANCE
from grasp_torque_opt.core.exceptions import FrameNotFound, GraspTorqueError, InputError
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.scenario import ContactSpec
from grasp_torque_opt.core.solution import Solution
from grasp_torque_opt.methods.adaptive import AdaptiveSettings, Refiner
from grasp_torque_opt.methods.dispatch import solve
import numpy as np
import pinocchio as pin

POLICIES = ('hold', 'zero')
#: A quaternion is accepted when | ||q|| - 1 | is at most this, then normalized.
QUATERNION_TOLERANCE = 1e-3
#: |joint position| above this [rad or m] is a corrupted message, not a hand.
MAX_ABS_JOINT_POSITION = 1e3
#: Names and frames in error messages are cut to this many characters.
SHOWN_NAME_LENGTH = 64
#: The input topics, as named in counters, stamps and messages (and ``gravity``, counted
#: from its first rejection: it is optional).
SOURCES = ('joint_states', 'contacts', 'external_wrench')
#: Largest accepted norm of a gravity input [m/s^2] (about 10 g).
MAX_GRAVITY = 100.0


@dataclass(frozen=True)
class CycleConfig:
    """
    Timing and safety settings of the cycle.

    Attributes:
        joint_state_timeout: joint states older than this stop commands [s] (> 0).
        contacts_timeout: once contacts have arrived on the topic, older than this
            stop commands [s]; 0 disables the check.
        wrench_timeout: the same for the external wrench [s]; 0 disables it.
        hold_time: how long after the last certified command a fault may last
            before the policy applies [s].
        fault_policy: ``hold`` or ``zero``.
        gravity_compensation: add the fingers' own gravity torques g(q).
        gravity: gravity in the base frame [m/s^2], shape (3,).
        certificate_tolerance: tolerance of the certificate (SI units).
        max_message_bytes: a message whose serialized form is longer than this is
            rejected before it is deserialized [bytes].
        max_joint_state_entries: a joint state with more names or positions than
            this is rejected unread [-].
        max_wrench_force: a load whose force norm exceeds this is rejected [N].
        max_wrench_torque: a load whose moment norm exceeds this is rejected [N m].
        max_contact_distance: a contact point farther than this from the base
            origin (at the cycle's configuration) stops commands [m].
        stamp_future_tolerance: a header stamp more than this ahead of the clock
            is rejected [s].
        cycle_budget: a cycle that takes longer publishes nothing (overrun) [s].
            Its solvers stop by the budget (with joint_state_timeout if smaller).
        method: ``tau-qp`` (the paper's polygon) or ``tau-qp-adaptive`` (the
            exact-cone optimum with certified bounds, docs/adaptive.md; DAQP).
        gravity_timeout: once gravity has arrived on its input, older than this
            stops commands [s]; 0 disables the check.
        compiled: run the cycle compiled (:mod:`grasp_torque_opt.control.compiled`)
            where it applies (tau-qp, sum of squares, ProxSuite, A of full column
            rank), else and on anything it cannot certify the Python cycle; False:
            the Python cycle always.
    """

    joint_state_timeout: float = 0.1
    contacts_timeout: float = 0.5
    wrench_timeout: float = 0.5
    hold_time: float = 0.1
    fault_policy: str = 'hold'
    gravity_compensation: bool = False
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    certificate_tolerance: float = DEFAULT_TOLERANCE
    max_joint_state_entries: int = 256
    max_message_bytes: int = 65536
    max_wrench_force: float = 1000.0
    max_wrench_torque: float = 100.0
    max_contact_distance: float = 1.0
    stamp_future_tolerance: float = 0.5
    cycle_budget: float = 0.05
    method: str = 'tau-qp'
    gravity_timeout: float = 0.5
    compiled: bool = True


@dataclass(frozen=True)
class ContactPoses:
    """
    Contact frames as estimated: pose i is contact i's frame in frame ``frame``.

    Attributes:
        frame: model frame the poses are expressed in ('' = the base frame).
        positions: contact points, shape (p, 3) [m].
        rotations: contact frame axes (columns x, y, z = inward normal), shape (p, 3, 3).
    """

    frame: str
    positions: np.ndarray
    rotations: np.ndarray


@dataclass(frozen=True)
class Inputs:
    """
    A snapshot of the latest valid inputs and their monotonic receipt times [s].

    ``contacts`` and ``wrench`` are None until one arrives (then the scenario's
    defaults are used); ``q`` is None until the first joint state. ``wrench`` is
    (frame, [F, M]) in that frame's axes. ``gravity`` is in base axes [m/s^2], None
    until one arrives (then ``CycleConfig.gravity`` and the scenario's load are used).
    """

    q: np.ndarray | None = None
    q_time: float | None = None
    contacts: ContactPoses | None = None
    contacts_time: float | None = None
    wrench: tuple[str, np.ndarray] | None = None
    wrench_time: float | None = None
    gravity: np.ndarray | None = None
    gravity_time: float | None = None


@dataclass
class CycleResult:
    """
    What one cycle decided.

    Attributes:
        command: effort command to publish now, in ``joints`` order [N m], or None.
        kind: ``solution`` (a certified command), ``zero`` (the zero policy) or
            ``none`` (nothing published).
        solution: the solve, if one ran.
        maps: its kinematic maps.
        gravity_torque: g(q) added to the solution, or None.
        fault: why no certified command was published ('' when healthy).
        cycle_time: wall time of the cycle [s] (0 for the watchdog's results).
    """

    command: np.ndarray | None
    kind: str
    solution: Solution | None = None
    maps: GraspMaps | None = None
    gravity_torque: np.ndarray | None = None
    fault: str = ''
    cycle_time: float = 0.0


@dataclass
class Counters:
    """
    Running totals, for diagnostics.

    ``solver_failures`` counts solves that raised or gave nothing certifiable
    (not the confirmed infeasible ones); ``fallback_solves`` certified
    solutions that came from the fallback backend after the first one failed;
    ``overruns`` cycles over ``cycle_budget``; ``max_cycle_time`` is the longest
    cycle [s].
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
    rejected: dict[str, int] = field(default_factory=lambda: dict.fromkeys(SOURCES, 0))


def _replaced(obj, **changes):
    """
    Return ``dataclasses.replace(obj, **changes)`` for a dataclass without ``__post_init__``.

    It copies the fields instead of calling ``__init__``: a fifth of the time, twice in
    every cycle (the inputs, the grasp).
    """
    new = object.__new__(type(obj))
    new.__dict__.update(obj.__dict__)
    new.__dict__.update(changes)
    return new


def show(name: str) -> str:
    """Quote a name in messages, cut to :data:`SHOWN_NAME_LENGTH` characters."""
    return name if len(name) <= SHOWN_NAME_LENGTH else name[:SHOWN_NAME_LENGTH] + '...'


def stamp_seconds(sec: int, nanosec: int) -> float:
    """Return a builtin_interfaces/Time as seconds (0.0 for an unstamped message)."""
    return sec + 1e-9 * nanosec


def _finite(a: np.ndarray, name: str) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    if not np.all(np.isfinite(a)):
        raise InputError(name, 'must be finite (NaN or Inf found)')
    return a


def quaternion_matrix(xyzw: np.ndarray, name: str) -> np.ndarray:
    """
    Rotation matrix of a unit quaternion (x, y, z, w).

    Raises:
        InputError: not finite, or its norm is off 1 by more than
            :data:`QUATERNION_TOLERANCE`.
    """
    q = _finite(xyzw, name)
    norm = float(np.linalg.norm(q))
    if abs(norm - 1.0) > QUATERNION_TOLERANCE:
        raise InputError(name, f'is not a unit quaternion (norm {norm:.6g})')
    x, y, z, w = q / norm
    return pin.Quaternion(w, x, y, z).toRotationMatrix()


class TorqueController:
    """
    The cycle of the node, on plain arrays.

    Args:
        setup: the grasp of the scenario: hand, default contacts and load,
            friction, limits, weights. Its hand is owned by this controller.
        config: timing and safety settings.
        solver_settings: solver tolerance and iteration caps.
        backend: QP backend, one of :data:`grasp_torque_opt.backends.BACKENDS`.
        warm_start: start each solve from the previous one (ProxSuite and DAQP;
            verified, with a cold redo in the same cycle).
        fallback: a second backend, asked in the same cycle when the first gives
            nothing certifiable; None for none.
    """

    def __init__(self, setup: GraspSetup, config: CycleConfig | None = None,
                 solver_settings: ProxSuiteSettings | None = None,
                 backend: str = 'proxsuite', warm_start: bool = False,
                 fallback: str | None = None) -> None:
        self.setup = setup
        self.config = config or CycleConfig()
        self.solver = make_solver(backend, solver_settings, warm_start)
        self.refiner: Refiner | None = None  # tau-qp-adaptive's, made when first used
        self.fallback = make_solver(fallback, solver_settings) if fallback else None
        self.inputs = Inputs()
        self.counters = Counters()
        self.last_command: np.ndarray | None = None
        self.last_command_time: float | None = None
        #: The last command returned for publishing, certified or the zero policy's: what
        #: the effort controller holds (it has no timeout) [N m].
        self.in_force: np.ndarray | None = None
        self.last: CycleResult | None = None
        self.fault = ''
        self.last_rejection = ''
        self._stamps: dict[str, tuple[float, float]] = {}  # source -> (stamp, receipt time)
        #: The scenario's load for a gravity input [m/s^2] (the object's weight moves with
        #: it), or None: the load does not depend on gravity.
        self.load_of_gravity = None
        #: The compiled cycle in use (None: the Python cycle), and why not when None.
        self.compiled_cycle: compiled.CompiledCycle | None = None
        self.compiled_reason = ''
        model = self.setup.hand.model
        self._model_joints = {model.names[j]: model.joints[j].idx_q
                              for j in range(1, model.njoints) if model.joints[j].nq == 1}
        #: The last accepted joint state's names, which of its entries are model joints,
        #: their indices in q, and the commanded joints it was checked against (a state
        #: with the same names skips the name checks).
        self._names: tuple | None = None

    # -- inputs ---------------------------------------------------------------------------

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
            self._reject(source, e)
            raise e

    def check_size(self, source: str, n: int) -> None:
        """
        Reject a message by its size alone, before it is read.

        Args:
            source: ``joint_states`` (``n`` names or positions, at most
                ``max_joint_state_entries``) or ``contacts`` (``n`` poses, exactly
                one per scenario contact).

        Raises:
            InputError: the size is out of bounds (counted as a rejection).
        """
        try:
            if source == 'joint_states' and n > self.config.max_joint_state_entries:
                limit = self.config.max_joint_state_entries
                raise InputError('joint_states', f'{n} entries, more than '
                                 f'max_joint_state_entries ({limit})')
            p = len(self.setup.contacts)
            if source == 'contacts' and n != p:
                raise InputError('contacts', f'{n} poses for {p} contacts')
        except InputError as e:
            self._reject(source, e)
            raise

    def _check_stamp(self, source: str, stamp: float, clock: float | None, now: float) -> None:
        """
        Apply the header stamp rule (docs/node.md, "Input checks").

        0 is an unstamped message: accepted, not compared. A stamp more than
        ``stamp_future_tolerance`` ahead of ``clock`` (when the clock runs, > 0)
        is rejected. A stamp before the topic's mark is rejected (out of order),
        unless the mark is itself stale by receipt time: a restarted publisher
        or a rewound clock recovers after the topic's timeout. The mark is the
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
        c = self.config
        t = {'joint_states': c.joint_state_timeout, 'contacts': c.contacts_timeout,
             'external_wrench': c.wrench_timeout, 'gravity': c.gravity_timeout}[source]
        return t if t > 0 else c.joint_state_timeout

    def _keep_stamp(self, source: str, stamp: float, now: float, clock: float | None) -> None:
        if stamp != 0.0:
            mark = min(stamp, clock) if clock is not None and clock > 0.0 else stamp
            self._stamps[source] = (mark, now)

    def update_joint_state(self, names: list[str], positions: list[float], now: float,
                           stamp: float = 0.0, clock: float | None = None) -> None:
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

        Raises:
            InputError: more than ``max_joint_state_entries`` entries, length
                mismatch, empty or duplicate name, a commanded joint missing, a
                used position not finite or beyond :data:`MAX_ABS_JOINT_POSITION`,
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
                checked = self._checked_names(names, positions, q)
            self._check_stamp('joint_states', stamp, clock, now)
        except InputError as e:
            self._reject('joint_states', e)
            raise
        if checked is not None:
            self._names = checked
        self._keep_stamp('joint_states', stamp, now, clock)
        self.inputs = _replaced(self.inputs, q=q, q_time=now)

    def _checked_names(self, names: list[str], positions: list[float], q: np.ndarray
                       ) -> tuple:
        """
        Check a joint state's names and used positions and write them into q.

        Returns:
            What :meth:`update_joint_state` keeps to skip the name checks next time.

        Raises:
            InputError: as :meth:`update_joint_state` says.
        """
        if len(names) != len(positions):
            raise InputError('joint_states', f'{len(names)} names but '
                             f'{len(positions)} positions')
        if len(set(names)) != len(names):
            dup = next(n for n, k in Counter(names).items() if k > 1)
            raise InputError('joint_states', f"duplicate joint name '{show(dup)}'")
        if any(not n for n in names):
            raise InputError('joint_states', 'empty joint name')
        given = set(names)
        missing = [n for n in self.setup.hand.joints if n not in given]
        if missing:
            raise InputError('joint_states', 'missing commanded joint(s) '
                             f"{', '.join(missing[:4])}")
        used, to = [], []
        for k, (name, value) in enumerate(zip(names, positions)):
            iq = self._model_joints.get(name)
            if iq is None:
                continue
            if not math.isfinite(value):
                raise InputError('joint_states', f"position of '{name}' is not finite")
            if abs(value) > MAX_ABS_JOINT_POSITION:
                raise InputError('joint_states', f"position of '{name}' is {value:.6g}, "
                                 f'beyond +-{MAX_ABS_JOINT_POSITION:g}')
            q[iq] = value
            used.append(k)
            to.append(iq)
        return (list(names), np.array(used, dtype=np.intp), np.array(to, dtype=np.intp),
                self.setup.hand.joints)

    def update_contacts(self, frame: str, positions: np.ndarray, quaternions: np.ndarray,
                        now: float, stamp: float = 0.0, clock: float | None = None) -> None:
        """
        Take contact frames: one pose per scenario contact, in model frame ``frame``.

        Args:
            frame: model frame of the poses ('' = the base frame).
            positions: contact points, shape (p, 3) [m].
            quaternions: contact frame orientations (x, y, z, w), shape (p, 4).
            now: monotonic receipt time [s].
            stamp: header stamp [s] (0: unstamped).
            clock: the clock the stamps are on, now [s] (None: not checked ahead).

        Raises:
            InputError: wrong count or shape, unknown frame, non-finite values, a
                non-unit quaternion, a bad stamp. The contacts are not kept. (The
                distance from the base is checked in the cycle, where the frame
                is placed.)
        """
        positions = np.asarray(positions, dtype=float)
        quaternions = np.asarray(quaternions, dtype=float)
        self.check_size('contacts', len(positions))
        try:
            p = len(self.setup.contacts)
            if positions.shape != (p, 3) or quaternions.shape != (p, 4):
                raise InputError('contacts', f'positions of shape {positions.shape} and '
                                 f'quaternions of shape {quaternions.shape}, expected '
                                 f'({p}, 3) and ({p}, 4)')
            model = self.setup.hand.model
            if frame and not model.existFrame(frame):
                raise FrameNotFound('contacts.header.frame_id', show(frame),
                                    {f.name for f in model.frames})
            _finite(positions, 'contacts.poses.position')
            rotations = np.array([quaternion_matrix(quaternions[i],
                                                    f'contacts.poses[{i}].orientation')
                                  for i in range(p)])
            self._check_stamp('contacts', stamp, clock, now)
        except InputError as e:
            self._reject('contacts', e)
            raise
        self._keep_stamp('contacts', stamp, now, clock)
        self.inputs = dataclasses.replace(
            self.inputs, contacts=ContactPoses(frame, positions, rotations), contacts_time=now)

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
            model = self.setup.hand.model
            if frame and not model.existFrame(frame):
                raise FrameNotFound('external_wrench.header.frame_id', show(frame),
                                    {f.name for f in model.frames})
            w = np.concatenate((_finite(force, 'external_wrench.wrench.force'),
                                _finite(torque, 'external_wrench.wrench.torque')))
            if w.shape != (6,):
                raise InputError('external_wrench.wrench', f'{w.size} values, expected 6')
            c = self.config
            for part, v, bound, key, unit in ((
                    'force', w[:3], c.max_wrench_force, 'max_wrench_force', 'N'), (
                    'torque', w[3:], c.max_wrench_torque, 'max_wrench_torque', 'N m')):
                with np.errstate(over='ignore'):  # 1e308 entries: an infinite norm
                    norm = float(np.linalg.norm(v))
                if norm > bound:
                    raise InputError(f'external_wrench.wrench.{part}',
                                     f'norm {norm:.6g} {unit} exceeds {key} '
                                     f'({bound} {unit})')
            self._check_stamp('external_wrench', stamp, clock, now)
        except InputError as e:
            self._reject('external_wrench', e)
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
                :data:`MAX_GRAVITY`, a bad stamp. The vector is not kept.
        """
        try:
            base = self.setup.hand.base_frame
            if frame not in ('', base) and rotation is None:
                raise InputError('gravity.header.frame_id', f"'{show(frame)}' is not the "
                                 f"hand's base frame '{base}' (nor empty), and cannot be "
                                 f'transformed ({unresolved})')
            g = _finite(vector, 'gravity.vector')
            if g.shape != (3,):
                raise InputError('gravity.vector', f'{g.size} values, expected 3')
            if rotation is not None:
                g = _finite(rotation, 'gravity.header.frame_id transform') @ g
            with np.errstate(over='ignore'):
                norm = float(np.linalg.norm(g))
            if norm > MAX_GRAVITY:
                raise InputError('gravity.vector', f'norm {norm:.6g} m/s^2 exceeds '
                                 f'{MAX_GRAVITY:g} m/s^2')
            self._check_stamp('gravity', stamp, clock, now)
        except InputError as e:
            self._reject('gravity', e)
            raise
        self._keep_stamp('gravity', stamp, now, clock)
        self.inputs = dataclasses.replace(self.inputs, gravity=g, gravity_time=now)

    def _reject(self, source: str, error: InputError) -> None:
        self.counters.rejected[source] = self.counters.rejected.get(source, 0) + 1
        self.last_rejection = str(error)  # names the field, e.g. contacts.poses[0]...

    # -- the cycle ------------------------------------------------------------------------

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
        if i.gravity_time is not None and c.gravity_timeout > 0 and \
                now - i.gravity_time > c.gravity_timeout:
            return f'gravity stale ({now - i.gravity_time:.3f} s > {c.gravity_timeout} s)'
        return ''

    def grasp_at(self, inputs: Inputs, jacobians: bool = False
                 ) -> tuple[GraspSetup, np.ndarray | None]:
        """
        Return the grasp of a snapshot of inputs, and g(q) if compensated.

        With ``jacobians``, the joint Jacobians are computed with the placements (the
        compiled cycle reads both from the hand's Pinocchio data).

        Raises:
            InputError: a contact point beyond ``max_contact_distance``, or the
                contacts cannot be placed on their links.
        """
        setup = self.setup
        hand = setup.hand
        q = inputs.q
        model, data = hand.model, hand.data
        if jacobians:
            pin.computeJointJacobians(model, data, q)
            pin.updateFramePlacements(model, data)
        else:
            pin.framesForwardKinematics(model, data, q)
        contacts = setup.contacts
        if inputs.contacts is not None:
            cp = inputs.contacts
            oMF = data.oMf[model.getFrameId(cp.frame)] if cp.frame else pin.SE3.Identity()
            contacts = []
            limit = self.config.max_contact_distance
            for i, (spec, p, R) in enumerate(zip(setup.contacts, cp.positions, cp.rotations)):
                distance = float(np.linalg.norm(oMF.act(p)))
                if distance > limit:
                    raise InputError(f'contacts.poses[{i}].position',
                                     f'is {distance:.6g} m from the base origin, beyond '
                                     f'max_contact_distance ({limit} m)')
                R_base = oMF.rotation @ R
                oMl = data.oMf[model.getFrameId(spec.link)]
                contacts.append(ContactSpec(link=spec.link, position=oMl.actInv(oMF.act(p)),
                                            normal=R_base[:, 2], tangent=R_base[:, 0]))
        wrench = setup.external_wrench
        if inputs.wrench is not None:
            frame, w = inputs.wrench
            R = data.oMf[model.getFrameId(frame)].rotation if frame else np.eye(3)
            wrench = np.concatenate((R @ w[:3], R @ w[3:]))
        elif inputs.gravity is not None and self.load_of_gravity is not None:
            wrench = self.load_of_gravity(inputs.gravity)
        g = None
        if self.config.gravity_compensation:
            model.gravity.linear = np.asarray(
                self.config.gravity if inputs.gravity is None else inputs.gravity, dtype=float)
            g = pin.computeGeneralizedGravity(model, data, q)[hand.idx_v].copy()
        return _replaced(setup, q=q, contacts=contacts, external_wrench=wrench,
                         torque_offset=g), g

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
        fast = self._compiled(self.setup)
        setup, g = self.grasp_at(inputs, jacobians=fast is not None)
        solver, fallback, handed_back = self.solver, self.fallback, ''
        if fast is not None:
            sol, maps = fast.solve(setup, None if deadline is None else
                                   deadline - time.perf_counter(), kinematics=False)
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
        self.compiled_cycle = None if why else compiled.CompiledCycle(setup, self.solver, tol)
        return self.compiled_cycle

    def _refiner(self) -> Refiner | None:
        """tau-qp-adaptive's rounds (kept across cycles, warm as the solver is), else None."""
        if self.config.method != 'tau-qp-adaptive':
            return None
        warm = getattr(self.solver, 'warm_start', False)
        settings = getattr(self.solver, 'settings', None)
        wanted = AdaptiveSettings(warm_start=warm,
                                  eps_abs=getattr(settings, 'eps_abs', AdaptiveSettings.eps_abs),
                                  max_iter=getattr(settings, 'max_iter',
                                                   AdaptiveSettings.max_iter))
        if self.refiner is None or self.refiner.settings != wanted:
            self.refiner = Refiner(wanted)
        return self.refiner

    def gate(self, solution: Solution, g: np.ndarray | None) -> tuple[np.ndarray | None, str]:
        """Check a command last before it leaves: certified, finite, sized, within limits."""
        if not solution.optimal:
            return None, f'no certified solution ({solution.status}: {solution.message})'
        cmd = solution.tau + (0.0 if g is None else g)
        lim = self.setup.hand.torque_limits
        if cmd.shape != lim.shape:
            return None, f'command has {cmd.size} values for {lim.size} joints'
        if (np.abs(cmd) <= lim).all():  # False for NaN as well
            return cmd, ''
        if not np.all(np.isfinite(cmd)):
            return None, 'command not finite'
        if np.any(np.abs(cmd) > lim):
            k = int(np.argmax(np.abs(cmd) - lim))
            return None, f'command over the limit at {self.setup.hand.joints[k]}'
        return cmd, ''

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
        self.counters.cycles += 1
        result = self._attempt(now, t0 + self.budget())
        elapsed = time.perf_counter() - t0
        self.counters.max_cycle_time = max(self.counters.max_cycle_time, elapsed)
        if elapsed > self.config.cycle_budget:
            self.counters.overruns += 1
            if result.kind == 'solution':
                result = self._faulted(now, f'cycle overrun ({1e3 * elapsed:.1f} ms > '
                                       f'cycle_budget {1e3 * self.config.cycle_budget:.1f} ms)',
                                       result.solution, result.maps, result.gravity_torque)
        late = self.stale(now + elapsed) if result.kind == 'solution' else ''
        if late:
            result = self._faulted(now + elapsed, f'inputs went stale during the cycle: {late}',
                                   result.solution, result.maps, result.gravity_torque)
        if result.kind == 'solution':
            if self.fault:
                self.counters.recoveries += 1
            self.fault = ''
            self.last_command, self.last_command_time = result.command, now
            self.in_force = result.command
            self.counters.commands += 1
            if self.fallback is not None and result.solution.backend == self.fallback.name:
                self.counters.fallback_solves += 1
            self.last = result
        result.cycle_time = elapsed
        return result

    def _attempt(self, now: float, deadline: float) -> CycleResult:
        """Solve and gate; a certified command is returned, not yet committed."""
        reason = self.stale(now)
        if reason:
            return self._faulted(now, reason)
        try:
            sol, maps, g = self.solve_inputs(self.inputs, deadline)
        except InputError as e:
            return self._faulted(now, f'inputs do not make a grasp: {e}')
        except GraspTorqueError as e:
            self.counters.solver_failures += 1
            return self._faulted(now, f'solver failed: {e}')
        except Exception as e:  # noqa: BLE001 -- a control loop fails safe, it does not die
            self.counters.solver_failures += 1
            return self._faulted(now, f'cycle failed: {type(e).__name__}: {e}')
        if sol.status == 'failed':
            self.counters.solver_failures += 1
        cmd, why = self.gate(sol, g)
        if cmd is None:
            return self._faulted(now, why, sol, maps, g)
        return CycleResult(cmd, 'solution', sol, maps, g)

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
        return self._faulted(now, reason) if reason else None

    def _faulted(self, now: float, reason: str, sol: Solution | None = None,
                 maps: GraspMaps | None = None, g: np.ndarray | None = None) -> CycleResult:
        if not self.fault:
            self.counters.faults += 1
        self.fault = reason
        held = (self.last_command_time is not None
                and now - self.last_command_time <= self.config.hold_time)
        if not held and self.config.fault_policy == 'zero':
            result = self._zero(reason, sol, maps, g)
        else:
            result = CycleResult(None, 'none', sol, maps, g, reason)
        self.last = result
        return result

    def _zero(self, reason: str, sol: Solution | None = None, maps: GraspMaps | None = None,
              g: np.ndarray | None = None) -> CycleResult:
        cmd = np.zeros(self.setup.hand.m)
        self.counters.zero_commands += 1
        self.in_force = cmd
        return CycleResult(cmd, 'zero', sol, maps, g, reason)

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
        lim = self.setup.hand.torque_limits
        if self.in_force.shape == lim.shape and np.all(np.abs(self.in_force) <= lim):
            return result if result is not None and result.command is not None else None
        why = result.fault if result is not None else self.stale(now)
        reason = 'the command in force exceeds the new torque_limits' + (
            f' ({why})' if why else '')
        if not self.fault:
            self.counters.faults += 1
        self.fault = reason
        self.last = self._zero(reason)
        return self.last
