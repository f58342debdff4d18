# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The object loop: an impedance with integral action on the object, a squeeze after friction.

A fully actuated hand under torque control is in equilibrium for one load only: the one
planned. The object loop notices the object moving in the hand and pushes back, through
the grasp, inside the cones.

**The error.** The fingertips give the object's displacement and rotation from a
reference (:class:`~grasp_torque_opt.core.object_from_hand.ObjectFromHand`: the rigid
motion that best carries the contact points of the reference configuration to where
they are now), e = [translation, rotation vector], base axes, about the object origin.
Its rate edot is e's finite difference, low-passed (``object_loop.velocity_filter``):
joint states carry no trusted velocities.

**The reference** is taken at the configuration of the loop's first cycle and re-taken
at every cycle for ``object_loop.settle_time`` seconds: the loop pushes only once the
hand has settled on the object under the node's own command (the scenario's q is not
where a real hand settles). The settling starts again when the loop is turned on again,
when the grasp's contact set changes (other links), and after a gap in the joint states
longer than ``joint_state_timeout``.

**The wrench.** The hand adds to what it applies on the object the restoring wrench

    w_r = -(K e + D edot + Ki integral(e dt))

(K, D, Ki diagonal: one value for the force rows, one for the moment rows). With the
tau-QP's convention G f = -w_ext (docs/design.md), the load planned is w_ext - w_r:
what is certified is the grasp balancing that load, inside the cones and the torque
limits, as for every load. The integral's wrench is bounded: its force by
``object_loop.max_integral_ratio`` times the scenario's weight, its moment by that force
times the farthest contact's distance from the object origin (as the effort
estimation's correction is bounded); the whole w_r by ``object_loop.max_force_ratio``
likewise.

**Slip.** A contact's residual is its point's distance from the rigid motion that best
fits all the points (a finger sliding on the object, or off it); its slip is how far the
residual rose above its own low-passed value (time constant ``object_loop.slip_memory``):
what slid lately, so that a slip once over stops counting.

**Anti-windup.** The integral is frozen while a contact slips (its slip beyond
``object_loop.slip_residual``: the error is then no object motion the grasp can undo),
and unwound (decays with ``object_loop.unwind_time``) after
a cycle that gave no certified command (infeasible, failed, faulted) or whose command
had a joint at its torque limit (``LIMIT_FRACTION`` of it).

**The squeeze.** The grasp's minimum normal force follows the friction usage measured
at each contact (0: no tangential load, 1: at the cone): above ``squeeze.raise_at`` it
rises at ``squeeze.rate`` [N/s] up to ``squeeze.max_normal_force``, below
``squeeze.relax_at`` it falls back at ``squeeze.relax_rate`` to the scenario's
``min_normal_force`` (slower: a shake's next peak finds the squeeze still there); it
does not rise after a cycle at a torque limit or without a certified command (the QP
keeps the torque limits; the squeeze does not ask past them).
The usage comes from a source: by default (``slip``) the contact's slip over
``object_loop.slip_residual`` (a finger sliding on the object), which a hand without
torque or tactile sensing can measure; another source (a tactile
plug-in's per-contact normal and tangential forces) sets it with
:meth:`Squeeze.measured` and its time, and is used while fresh. The minimum normal force
moves in steps of ``STEP`` (the compiled cycle is built again for each).

**Compiled.** Where the fingertips' estimate is compiled (the hand a tree the module
takes), the engaged step (estimate, slip, rate, integral, wrench) is one call of the
compiled module's ``loop_step`` (src/object_loop.hpp), by the rules above; this numpy
code is its reference (``ObjectLoop.compiled`` False), held to it in the tests.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
import math

from grasp_torque_opt.core.hand import Hand
from grasp_torque_opt.core.object_from_hand import ObjectFromHand
from grasp_torque_opt.core.scenario_fields import ContactSpec
from grasp_torque_opt.native.loader import fast_cycle
import numpy as np
import pinocchio as pin

#: A joint's command within this fraction of its torque limit counts as at the limit.
LIMIT_FRACTION = 0.98
#: The squeeze's minimum normal force moves in steps of this [N].
STEP = 0.02
#: Why the integral did not move, by the compiled step's code (0: it moved).
FROZEN = ('', 'no certified command', 'at a torque limit', 'a contact slips')


@dataclass(frozen=True)
class LoopGains:
    """
    The object loop's settings (``object_loop.*`` and ``squeeze.*``).

    Attributes:
        stiffness: K on the position error [N/m].
        rotational_stiffness: K on the rotation error [N m/rad].
        damping: D on the velocity [N s/m].
        rotational_damping: D on the angular velocity [N m s/rad].
        integral: Ki on the integrated position error [N/(m s)].
        rotational_integral: Ki on the integrated rotation error [N m/(rad s)].
        max_integral_ratio: the integral's force bound over the scenario's weight [-].
        max_force_ratio: the whole restoring force's bound over the weight [-].
        settle_time: the reference is re-taken for this long [s].
        velocity_filter: the error rate's low-pass time constant [s].
        unwind_time: the integral's decay time constant at a limit [s].
        slip_residual: a contact whose residual rose this far lately slips [m].
        slip_memory: the residual's low-pass time constant (what is lately) [s].
        squeeze: the squeeze on.
        raise_at, relax_at: friction usages where the squeeze rises, relaxes [-].
        rate: the squeeze's rate of rise [N/s].
        relax_rate: its rate of relaxing [N/s].
        max_normal_force: its ceiling [N].
        usage_timeout: a measured usage older than this is not used [s].
    """

    stiffness: float = 600.0
    rotational_stiffness: float = 0.0
    damping: float = 4.0
    rotational_damping: float = 0.0
    integral: float = 6000.0
    rotational_integral: float = 0.0
    max_integral_ratio: float = 0.5
    max_force_ratio: float = 1.0
    settle_time: float = 0.2
    velocity_filter: float = 0.01
    unwind_time: float = 0.1
    slip_residual: float = 1e-3
    slip_memory: float = 0.2
    squeeze: bool = False
    raise_at: float = 0.5
    relax_at: float = 0.2
    rate: float = 2.0
    relax_rate: float = 0.5
    max_normal_force: float = 1.0
    usage_timeout: float = 0.05

    @cached_property
    def per_axis(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """K, D and Ki for each axis of the error [x, y, z, rotation x, y, z] (made once)."""
        return (np.repeat([self.stiffness, self.rotational_stiffness], 3),
                np.repeat([self.damping, self.rotational_damping], 3),
                np.repeat([self.integral, self.rotational_integral], 3))

    @cached_property
    def packed(self) -> np.ndarray:
        """Give the settings the compiled step takes (src/object_loop.hpp's LoopSettings)."""
        return np.concatenate((*self.per_axis, (
            self.slip_memory, self.velocity_filter, self.unwind_time, self.slip_residual,
            self.max_integral_ratio, self.max_force_ratio)))


def scales(w: np.ndarray, force: float, lever: float) -> tuple[float, float]:
    """
    Return the factors :func:`bounded` scales a wrench (an array, (6,)) by (1.0: within).

    In floats, not numpy: the loop bounds three wrenches a cycle, and numpy's dispatch
    on 3-vectors cost more than the arithmetic.
    """
    x, y, z, a, b, c = w.tolist()
    norm_f, norm_m = math.sqrt(x * x + y * y + z * z), math.sqrt(a * a + b * b + c * c)
    limit = force * lever
    return (force / norm_f if norm_f > force else 1.0,
            limit / norm_m if norm_m > limit else 1.0)


def bounded(w: np.ndarray, force: float, lever: float) -> np.ndarray:
    """Scale a wrench's force to at most ``force`` and its moment to ``force * lever``."""
    out = np.array(w, dtype=float)
    s_f, s_m = scales(out, force, lever)
    if s_f != 1.0:
        out[:3] *= s_f
    if s_m != 1.0:
        out[3:] *= s_m
    return out


class ObjectLoop:
    """
    The restoring wrench and its state, kept across cycles.

    Attributes:
        wrench: the last restoring wrench w_r, about the object origin, base axes, (6,).
        integral: the integrated error [m s, rad s], (6,).
        error: the last error e [m, rad], (6,) (zeros while settling).
        rate: the last filtered rate of e [m/s, rad/s], (6,).
        residual: per contact, the distance from the rigid motion at the last cycle [m].
        slip: per contact, the residual's rise over its low-passed value
            (``object_loop.slip_memory``): how far the contact slid lately [m].
        engaged: the reference is taken and the loop pushes.
        why_frozen: why the integral did not move at the last cycle ('' when it did).
        changes: how many times the reference was taken (settlings started).
    """

    def __init__(self) -> None:
        """Start with no reference."""
        self.tracker: ObjectFromHand | None = None
        self.changes = 0
        #: The engaged step in one compiled call where the estimate is compiled (False:
        #: numpy's, the reference).
        self.compiled = True
        self.reset()
        self.squeeze = Squeeze()

    def reset(self) -> None:
        """Drop the reference and the integral: the next cycle starts a settling."""
        self.wrench, self.integral = np.zeros(6), np.zeros(6)
        self.error, self.rate = np.zeros(6), np.zeros(6)
        self.residual = self.slip = self._slow = np.zeros(0)
        self.engaged, self.why_frozen = False, ''
        self._start = self._last = None
        self._links: tuple[str, ...] | None = None
        self._previous: tuple[bool, bool] = (True, False)  # (certified, at a limit)
        self._lever: tuple | None = None  # (reference points, origin, lever): _lever_of's

    def after(self, certified: bool, command: np.ndarray | None, limits: np.ndarray,
              at_limit: bool | None = None) -> None:
        """
        Note the cycle's outcome: a certified command, and whether it was at a limit.

        ``at_limit``: whether it was, when the gate has told (``Cycle.gate``); None: found
        here from the command and the limits.
        """
        if at_limit is None:
            at_limit = command is not None and bool(
                (np.abs(command) >= LIMIT_FRACTION * limits).any())
        self._previous = (certified and command is not None, at_limit)

    def update(self, hand: Hand, contacts: list[ContactSpec], q: np.ndarray, now: float,
               origin: np.ndarray, weight: float | None, gains: LoopGains, gap: float
               ) -> np.ndarray:
        """
        Take one joint state (``q`` complete, at time ``now``); return w_r.

        Args:
            hand: the grasp's hand.
            contacts: its contacts (material points on their links).
            q: the configuration (coupled joints completed).
            now: the joint state's time [s].
            origin: the object origin, base frame [m].
            weight: the scenario's weight [N] (None: no bound known; no wrench).
            gains: the settings.
            gap: a longer time between cycles is a gap (``joint_state_timeout``) [s].
        """
        links = tuple(c.link for c in contacts)
        last, self._last = self._last, now
        if weight is None or not contacts:
            self.reset()
            return self.wrench
        if (links != self._links or self.tracker is None or last is None
                or not 0.0 < now - last <= gap):
            self._settle(hand, contacts, q, origin, now, links)
            return self.wrench
        dt = now - last
        if not self.engaged:
            self.tracker.reset(q, pin.SE3(np.eye(3), np.asarray(origin, dtype=float)))
            self.engaged = now - self._start >= gains.settle_time
            self.residual = self.slip = self._slow = np.zeros(len(contacts))
            return self.wrench
        if self.tracker.compiled is not None and self.compiled:
            return self._compiled_step(q, dt, origin, weight, gains)
        est = self.tracker.estimate(q)
        residual = est.residuals  # each point's distance from the rigid motion carried
        if self._slow.shape != residual.shape:
            self._slow = residual.copy()
        self.residual = residual
        self.slip = np.maximum(residual - self._slow, 0.0)
        self._slow = self._slow + dt / (gains.slip_memory + dt) * (residual - self._slow)
        error = np.concatenate((est.translation, est.rotation))
        a = dt / (gains.velocity_filter + dt)
        self.rate = self.rate + a * ((error - self.error) / dt - self.rate)
        self.error = error
        lever = self._lever_of(origin)
        self._integrate(error, dt, gains, weight, lever)
        k, d, ki = gains.per_axis
        w = -(k * error + d * self.rate + self._integral_wrench(ki, gains, weight, lever))
        self.wrench = bounded(w, gains.max_force_ratio * weight, lever)
        return self.wrench

    def _compiled_step(self, q: np.ndarray, dt: float, origin: np.ndarray, weight: float,
                       gains: LoopGains) -> np.ndarray:
        """Take the engaged step of :meth:`update` in one compiled call (its numpy rules)."""
        tracker = self.tracker
        certified, at_limit = self._previous
        (self.wrench, self.integral, self.error, self.rate, self.residual, self.slip,
         self._slow, frozen) = fast_cycle.loop_step(
            tracker.compiled, q, tracker.points0, tracker.pose0.translation, self._slow,
            self.rate, self.error, self.integral, dt, gains.packed, weight,
            self._lever_of(origin), certified, at_limit)
        self.why_frozen = FROZEN[frozen]
        return self.wrench

    def _lever_of(self, origin: np.ndarray) -> float:
        """Return the reference points' farthest distance from ``origin`` (kept per origin)."""
        points0, key = self.tracker.points0, np.asarray(origin, dtype=float).tobytes()
        kept = self._lever
        if kept is None or kept[0] is not points0 or kept[1] != key:
            kept = self._lever = (points0, key,
                                  float(np.max(np.linalg.norm(points0 - origin, axis=1))))
        return kept[2]

    def _settle(self, hand: Hand, contacts: list[ContactSpec], q: np.ndarray,
                origin: np.ndarray, now: float, links: tuple[str, ...]) -> None:
        """Start a settling: the reference taken here, no wrench, no integral."""
        self.reset()
        self._last, self._start, self._links = now, now, links
        self.changes += 1
        pose0 = pin.SE3(np.eye(3), np.asarray(origin, dtype=float))
        self.tracker = ObjectFromHand(hand, contacts, q, pose0, module=fast_cycle)

    def _integrate(self, error: np.ndarray, dt: float, gains: LoopGains, weight: float,
                   lever: float) -> None:
        """Move the integral by e dt, or freeze or unwind it (anti-windup)."""
        certified, at_limit = self._previous
        slipping = self.slip.size and float(self.slip.max()) > gains.slip_residual
        if not certified or at_limit:
            self.why_frozen = FROZEN[2 if certified else 1]
            self.integral = self.integral * (gains.unwind_time / (gains.unwind_time + dt))
            return
        if slipping:
            self.why_frozen = FROZEN[3]
            return
        self.why_frozen = ''
        self.integral = self.integral + error * dt
        ki = gains.per_axis[2]
        # Clamp the integral itself where its wrench is at its bound (no hidden windup);
        # a row whose Ki is zero keeps its integral (its wrench is zero whatever it is).
        w = ki * self.integral
        s_f, s_m = scales(w, gains.max_integral_ratio * weight, lever)
        if s_f != 1.0 or s_m != 1.0:
            scale = np.where(w != 0.0, np.repeat((s_f, s_m), 3), 1.0)
            self.integral = self.integral * scale

    def _integral_wrench(self, ki: np.ndarray, gains: LoopGains, weight: float,
                         lever: float) -> np.ndarray:
        """Return Ki times the integral, bounded."""
        return bounded(ki * self.integral, gains.max_integral_ratio * weight, lever)

    @property
    def previous(self) -> tuple[bool, bool]:
        """Give the last cycle's outcome noted: (a certified command, at a torque limit)."""
        return self._previous


class Squeeze:
    """
    The minimum normal force that follows the measured friction usage.

    Attributes:
        normal_force: the minimum normal force planned now [N] (None: the scenario's).
        usage: the last usage used, per contact (empty: none).
        source: where it came from ('slip', or the name a source gave).
    """

    def __init__(self) -> None:
        """Start at the scenario's minimum normal force."""
        self.normal_force: float | None = None
        self.usage = np.zeros(0)
        self.source = ''
        self._measured: tuple[np.ndarray, float, str] | None = None
        self._level = None
        self._last: float | None = None

    def measured(self, usage: np.ndarray, now: float, source: str) -> None:
        """Give a measured usage per contact (a tactile plug-in's), at time ``now`` [s]."""
        self._measured = (np.asarray(usage, dtype=float), now, source)

    def update(self, base: float, slip_usage: np.ndarray, now: float, gains: LoopGains,
               previous: tuple[bool, bool], gap: float) -> float:
        """
        Return the minimum normal force for this cycle [N].

        Args:
            base: the scenario's minimum normal force [N].
            slip_usage: the usage the slip evidence gives, per contact.
            now: the cycle's time [s].
            gains: the settings.
            previous: the last cycle's (certified command, at a torque limit).
            gap: a longer time between cycles moves nothing [s].
        """
        last, self._last = self._last, now
        level = base if self._level is None else self._level
        usage, self.source = slip_usage, 'slip'
        m = self._measured
        if m is not None and 0.0 <= now - m[1] <= gains.usage_timeout and np.all(
                np.isfinite(m[0])):
            usage, self.source = m[0], m[2]
        self.usage = usage
        dt = now - last if last is not None and 0.0 < now - last <= gap else 0.0
        worst = float(np.max(usage)) if usage.size else 0.0
        certified, at_limit = previous
        if worst > gains.raise_at and certified and not at_limit:
            level = min(level + gains.rate * dt, max(base, gains.max_normal_force))
        elif worst < gains.relax_at or not certified or at_limit:
            level = max(level - gains.relax_rate * dt, base)
        self._level = level
        self.normal_force = base + STEP * np.floor((level - base) / STEP + 1e-6)
        return self.normal_force

    def reset(self) -> None:
        """Back to the scenario's minimum normal force."""
        self.normal_force, self._level, self._last = None, None, None
