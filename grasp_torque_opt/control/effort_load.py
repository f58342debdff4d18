# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The load estimated from measured efforts, and the bounded integral action that follows it.

The grasp's statics backwards: the joints' measured torques tau_m (joint_states'
effort, what the driver applies: the node's command plus its impedance) less the
fingers' own gravity g(q) are J^T f; the least-squares contact wrenches f give the
wrench the hand applies, G f, and the load it holds is w_est = -G f (the tau-QP's
G f = -w_ext). w_est is low-passed (``effort_estimation.filter``), and the load the
cycle plans for is the model's load plus a correction b, moved by the integral action

    db/dt = (w_est - (w_model + b)) / T,     T = ``effort_estimation.time_constant``,

so that b tends to w_est - w_model: the feedforward takes over what the driver's
impedance held. b is bounded: its force by ``effort_estimation.max_load_ratio`` times the
scenario's weight, its moment by that force times the farthest contact's distance from
the object origin (:meth:`EffortLoad.bound`). The sum is planned and certified as every
load is: the estimate moves what is planned, never what is checked.

The mass-only estimate (``effort_estimation.mass_only``) integrates a mass error dm
instead, from the force error along the apparent gravity g_a:

    d(dm)/dt = k ((w_est - (w_model + b)) . g_a / |g_a|^2) / T,     b = dm g_a,

k = min(1, |g_a|^2 / |g|^2), g the configured gravity (a force error says less of the
mass the less the apparent gravity: at a tenth of g its noise would be integrated ten
times over), |dm| at most ``max_load_ratio`` times the scenario's mass. A mass is what does not
change when the hand shakes: b follows the apparent gravity at once (a force learned at
1 g and held through a shake was 0.3 N short at 2 g and 0.3 N over at 0 g), and a
frozen dm (the gate, below) stays right through the shake.

An error beyond ``IMPLAUSIBLE`` times the force bound is no load the correction could
meet: the hand is not holding the modelled object alone (it is still being placed in
the hand, or held by something else: in the simulation, the pinned ball before release
read -1.6 N against the model's +1.47 N, and integrating it put the correction at its
bound at the moment of release, a 2.6 to 4.5 mm drop on a ball 3 to 5 mm off its
place). Then the correction decays towards zero with the same time constant: the
model's load is planned until the measurement is plausible again.

**What the efforts are** (``effort_estimation.effort_report``): ``applied``, the torque
each joint applies (current sensing; the simulated hand's default); ``commanded``, the
node's own last command echoed (the Allegro V5's driver). An echo holds no news of the
load: integrated, b moves the command, the echo follows, and b runs to its bound (4.4 s
on a still simulated hand). The applied torque is then the command plus the driver's
impedance, Kp (q_ref - q) (:func:`applied_torque`): ``effort_estimation.driver_stiffness``
Kp and ``driver_reference`` q_ref (empty: the scenario's grasp configuration; the
simulated driver holds that before release and the settled configuration after, a few
hundredths of a millimetre away at the fingertips).

**The gate** (:class:`Agreement`): the efforts give the load only while the fingertips
and the object agree, the object held still and rigidly. A slipping ball pulls on the
fingers less than its weight (the hand does not hold it, it falls through it), and a
ball off its place is touched elsewhere than the contacts the estimate inverts through:
both read as a lighter load, and the correction, integrated, gave way (-0.7 N, its
bound, on a ball 5 mm off its place, before and just after release). From where the
fingertips place the object
(:class:`~grasp_torque_opt.core.object_from_hand.ObjectFromHand`), nothing is
integrated while

- the object moves faster than ``effort_estimation.max_object_speed`` (the fastest
  contact point under the object's motion, the least-squares slope of its displacement
  over ``effort_estimation.speed_window``): the correction is held at its value one
  window before (the readings the slope needed to see the motion are undone);
- a fingertip is farther than ``effort_estimation.max_residual`` from the object's
  rigid motion since the grasp's start (a slip or roll of a tip, the object not where
  the scenario says): the correction also decays towards zero with the integral's time
  constant, as for an implausible reading. What was learned was learned on another
  grasp: on a ball 1 mm off its place that slipped at release, a correction held at
  -0.28 N left it 3.1 mm down where the model's load held it.

The estimate starts again from the first reading after.
"""

from __future__ import annotations

from collections import deque

import numpy as np

#: A load error beyond this many times the correction's force bound is not integrated.
IMPLAUSIBLE = 2.0
#: What joint_states' effort may be (``effort_estimation.effort_report``).
EFFORT_REPORTS = ('applied', 'commanded')


def applied_torque(effort: np.ndarray, report: str, stiffness: float,
                   reference: np.ndarray, q: np.ndarray) -> np.ndarray:
    """
    Return the torque the joints apply [N m], from the efforts a driver reports.

    Args:
        effort: joint_states' effort, actuators [N m], shape (m,).
        report: ``applied`` (the effort is it) or ``commanded`` (the node's last command:
            the driver adds stiffness (reference - q)).
        stiffness: the driver's Kp [N m/rad].
        reference: the position its impedance holds [rad], shape (m,).
        q: the actuators' positions [rad], shape (m,).
    """
    if report == 'applied':
        return effort
    return effort + stiffness * (np.asarray(reference, dtype=float) - q)


class Agreement:
    """
    The gate: whether the fingertips and the object agree (held still and rigidly).

    Attributes:
        speed: the speed of the fastest contact point under the object's motion [m/s],
            the slope of its displacement over the window (inf until the window is full).
        state: why the correction is frozen ('' while the gate is open).
        off_hold: a fingertip is off the rigid hold (then the correction unwinds).
    """

    def __init__(self) -> None:
        """Start closed: no motion seen yet."""
        self.speed = float('inf')
        self.state = 'frozen: starting'
        self.off_hold = False
        self._seen: deque = deque()

    def check(self, tips, arms: np.ndarray, now: float, window: float, gap: float,
              limits: tuple[float, float]) -> str:
        """
        Take where the fingertips place the object; return why frozen ('' for open).

        Args:
            tips: :meth:`ObjectFromHand.estimate
                <grasp_torque_opt.core.object_from_hand.ObjectFromHand.estimate>` now.
            arms: the contact points less the object origin, base axes [m], shape (p, 3).
            now: the cycle's time [s].
            window: the speed is the least-squares slope of the displacement over this
                much time [s] (a slope, not a difference: the encoders' noise averages).
            gap: a longer time between readings starts the window again [s].
            limits: ``max_object_speed`` [m/s] and ``max_residual`` [m].
        """
        seen = self._seen
        if seen and not 0.0 < now - seen[-1][0] <= gap:
            seen.clear()
        seen.append((now, np.concatenate((tips.translation, tips.rotation))))
        while now - seen[0][0] > window:
            seen.popleft()
        self.speed = float('inf')
        if len(seen) >= 3 and now - seen[0][0] >= 0.5 * window:
            t = np.array([x[0] for x in seen])
            A = np.column_stack((t - t.mean(), np.ones_like(t)))
            slope = np.linalg.lstsq(A, np.array([x[1] for x in seen]), rcond=None)[0][0]
            points = slope[:3] + np.cross(slope[3:], arms)
            self.speed = float(np.linalg.norm(points, axis=1).max())
        max_speed, max_residual = limits
        self.off_hold = not tips.residual <= max_residual
        if self.off_hold:
            self.state = (f'frozen: a fingertip {1e3 * tips.residual:.3g} mm off the '
                          f'rigid hold (max_residual {1e3 * max_residual:g} mm)')
        elif not self.speed <= max_speed:
            self.state = ('frozen: starting' if not np.isfinite(self.speed) else
                          f'frozen: the object moves at {1e3 * self.speed:.3g} mm/s '
                          f'(max_object_speed {1e3 * max_speed:g} mm/s)')
        else:
            self.state = ''
        return self.state


class EffortLoad:
    """
    The estimate and the correction, kept across cycles.

    Attributes:
        estimate: the filtered load estimate w_est, base axes about the origin, or None.
        correction: b, added to the model's load [N, N m], shape (6,).
        off: why the feature is off ('' while on or not asked).
        said: whether ``off`` was said (the node logs it once).
    """

    def __init__(self) -> None:
        """Start with no estimate and no correction."""
        self.estimate: np.ndarray | None = None
        self.correction = np.zeros(6)
        self.mass = 0.0
        self.off = ''
        self.said = False
        self._last: float | None = None
        self._history: deque = deque()
        #: The gate (:class:`Agreement`), None: none (no fingertips' estimate).
        self.agreement: Agreement | None = None

    def reset(self) -> None:
        """Drop the estimate and the correction (inputs lost, the feature turned off)."""
        self.estimate, self.correction, self._last = None, np.zeros(6), None
        self.mass = 0.0
        self.agreement = None
        self._history.clear()

    def turn_off(self, why: str) -> None:
        """Stop estimating, for a reason said once."""
        if not self.off:
            self.off, self.said = why, False
        self.reset()

    @staticmethod
    def measured(G: np.ndarray, J: np.ndarray, effort: np.ndarray,
                 gravity_torque: np.ndarray | None) -> np.ndarray:
        """
        Return the load the measured efforts hold: -G f, J^T f = tau_m - g(q) (least squares).

        Only the contact forces are estimated, not the soft-finger torsional moments: a
        fingertip's twist about its normal moves the joints little, and least squares
        over them turns small torque errors into large moments.

        Args:
            G: grasp matrix (6, 4p).
            J: hand Jacobian (4p, m) (per contact: force x, y, z, then the torsional
                moment).
            effort: measured actuator torques [N m], shape (m,).
            gravity_torque: g(q) on the actuators [N m], or None (none).
        """
        forces = np.arange(G.shape[1]) % 4 != 3
        tau = effort if gravity_torque is None else effort - gravity_torque
        f = np.linalg.lstsq(J[forces].T, tau, rcond=1e-6)[0]
        return -(G[:, forces] @ f)

    @staticmethod
    def bound(weight: float, ratio: float, positions: np.ndarray, origin: np.ndarray
              ) -> tuple[float, float]:
        """Return the correction's force and moment bounds [N, N m]."""
        force = ratio * weight
        lever = float(np.max(np.linalg.norm(positions - origin, axis=1))) if len(positions) \
            else 0.0
        return force, force * lever

    def update(self, measured: np.ndarray, model: np.ndarray, now: float, filter_s: float,
               time_constant: float, bounds: tuple[float, float], gap: float,
               gravity: np.ndarray | None = None, frozen: str = '', window: float = 0.0,
               unwind: bool = False, mass_bound: float = np.inf,
               nominal: float = 9.81) -> np.ndarray:
        """
        Take one measurement; return the correction b to add to the model's load.

        Args:
            measured: :meth:`measured` at this cycle.
            model: the load the cycle would plan without the correction.
            now: the cycle's time [s].
            filter_s: the estimate's low-pass time constant [s].
            time_constant: T of the integral action [s].
            bounds: the force and moment bounds (:meth:`bound`; the whole wrench's).
            gap: a longer time between cycles starts the filter again [s].
            gravity: the apparent gravity [m/s^2], base axes: the mass-only estimate, a
                mass error dm integrated from the force error along it, b = dm gravity
                (it follows the apparent gravity at once); None: the whole wrench.
            frozen: why the gate is closed ('' open): then the integral is held at its
                value ``window`` ago (before the motion was seen) and the estimate
                starts again at the first reading after.
            window: the gate's window [s] (:class:`Agreement`).
            unwind: frozen, the integral also decays towards zero with
                ``time_constant`` (a fingertip off the rigid hold: what was learned
                was learned on another grasp).
            mass_bound: |dm| at most this [kg] (the mass-only estimate).
            nominal: the gravity the integral's gain is set for [m/s^2]: below it, the
                mass error's gain falls as (|g_a| / nominal)^2.
        """
        if not np.all(np.isfinite(measured)):
            return self._out(gravity)
        last, self._last = self._last, now
        dt = now - last if last is not None and 0.0 < now - last <= gap else None
        decay = 1.0 if dt is None else time_constant / (time_constant + dt)
        if frozen:
            # Held at its value before the motion was seen (the window's oldest): the
            # readings of the window were integrated before the slope could tell.
            if self._history:
                _, self.correction, self.mass = self._history[0]
                self._history.clear()
            if unwind:  # the grasp is not the model's: back to it
                self.correction, self.mass = self.correction * decay, self.mass * decay
            self.estimate = None
            return self._out(gravity)
        if self._off_by(measured, model, gravity) > IMPLAUSIBLE * bounds[0]:
            # Not this object's load alone: back towards the model, and the filter starts
            # again from the first plausible measurement (it would carry this one).
            self.estimate = None
            self.correction, self.mass = self.correction * decay, self.mass * decay
            return self._out(gravity)
        if dt is None or self.estimate is None:
            self.estimate = measured.copy()
            return self._out(gravity)
        self.estimate = self.estimate + dt / (filter_s + dt) * (measured - self.estimate)
        error = self.estimate - model - self._out(gravity)
        gain = dt / (time_constant + dt)
        if gravity is None:
            self.correction = clipped(self.correction + gain * error, bounds)
        elif float(gravity @ gravity) > 0.0:
            # Weighed as a force at the nominal gravity would be: the less the apparent
            # gravity, the less a force error tells of the mass (its noise divided by
            # |g_a| is not integrated at full gain near weightlessness).
            square = float(gravity @ gravity)
            weight = min(1.0, square / nominal ** 2) if nominal > 0 else 1.0
            dm = weight * float(error[:3] @ gravity) / square
            self.mass = float(np.clip(self.mass + gain * dm, -mass_bound, mass_bound))
        self._remember(now, window)
        return self._out(gravity)

    def _out(self, gravity: np.ndarray | None) -> np.ndarray:
        """Return the correction: b, or the mass error times the apparent gravity."""
        if gravity is not None:
            self.correction = np.concatenate((self.mass * np.asarray(gravity, dtype=float),
                                              np.zeros(3)))
        return self.correction

    def _off_by(self, measured: np.ndarray, model: np.ndarray,
                gravity: np.ndarray | None) -> float:
        """Return the force error's norm [N] (along the apparent gravity, mass-only)."""
        error = (measured - model - self._out(gravity))[:3]
        if gravity is None:
            return float(np.linalg.norm(error))
        norm = float(np.linalg.norm(gravity))
        return abs(float(error @ gravity)) / norm if norm > 0 else 0.0

    def _remember(self, now: float, window: float) -> None:
        """Keep the integral of the gate's last window (its value before motion is seen)."""
        history = self._history
        history.append((now, self.correction.copy(), self.mass))
        while now - history[0][0] > window:
            history.popleft()


def clipped(b: np.ndarray, bounds: tuple[float, float]) -> np.ndarray:
    """Scale b's force and moment parts down to their bounds' norms."""
    out = b.copy()
    for part, limit in ((slice(0, 3), bounds[0]), (slice(3, 6), bounds[1])):
        norm = float(np.linalg.norm(out[part]))
        if norm > limit:
            out[part] *= limit / norm if norm > 0 else 0.0
    return out
