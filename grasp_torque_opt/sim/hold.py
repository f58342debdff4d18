# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
A hold episode: the certified torques (plus g(q) and an impedance) on the simulated hand.

What the node does for one grasp, without ROS: solve the scenario with the fingers'
gravity torques g(q0) as the torque offset (the node's ``gravity_compensation``),
command tau + g(q) with g at the measured configuration, and watch the object.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
import time

from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.scenario import Scenario
from grasp_torque_opt.core.solution import Solution
from grasp_torque_opt.methods import solve
from grasp_torque_opt.sim.model import build_model, SimSettings
from grasp_torque_opt.sim.simulator import friction_usage, HandSim, wrench_in_frame
import numpy as np


@dataclass(frozen=True)
class HoldSettings:
    """
    One hold episode.

    Attributes:
        kp: joint impedance stiffness [N m/rad].
        kd: joint impedance damping [N m s/rad].
        duration: simulated time after release [s].
        settle: simulated time the object is pinned while the fingers press [s].
        drift_limit: the object counts as held while it moves less than this [m].
        feedforward: factor on the certified torques (0: impedance alone, the control) [-].
        sample_period: period of the (time, drift, rotation) samples [s].
    """

    kp: float = 1.0
    kd: float = 0.01
    duration: float = 2.0
    settle: float = 0.2
    drift_limit: float = 1e-3
    feedforward: float = 1.0
    sample_period: float = 0.1


@dataclass(frozen=True)
class ContactReport:
    """
    One planned contact: certified against simulated wrench.

    Attributes:
        link: the contact's link.
        predicted: certified wrench [fx, fy, fz, mz], contact frame [N, N m].
        simulated: simulated wrench in the same frame [N, N m].
        usage_predicted: share of the planned friction cone the certified wrench uses [-].
        usage_simulated: share of the planned friction cone the simulated wrench uses [-].
        touching: the link touched the object when measured.
        rotation: the contact frame, columns x, y, z in base axes, shape (3, 3).
    """

    link: str
    predicted: np.ndarray
    simulated: np.ndarray
    usage_predicted: float
    usage_simulated: float
    touching: bool
    rotation: np.ndarray

    @property
    def force_error(self) -> float:
        """|f_sim - f_pred| / |f_pred| of the contact forces [-]."""
        return float(np.linalg.norm(self.simulated[:3] - self.predicted[:3])
                     / np.linalg.norm(self.predicted[:3]))


@dataclass
class HoldReport:
    """
    Outcome of a hold episode.

    Attributes:
        held: the object moved less than the drift limit for the whole episode.
        reason: why, in words.
        time: simulated time after release [s] (shorter when the object fell).
        drift: object displacement at the end [m].
        max_drift: largest displacement [m].
        rotation: object rotation at the end [rad].
        contacts: per planned contact, certified against simulated wrench
            (at the end, or at the last sample before the drift limit was passed).
        unplanned_force: force of other hand bodies on the object then [N].
        max_effort: largest joint torque applied, impedance included [N m].
        samples: (time [s], drift [m], rotation [rad]) every sample period.
        wall_time: wall-clock time of the episode [s].
        solution: the certified solution commanded.
    """

    held: bool
    reason: str
    time: float
    drift: float
    max_drift: float
    rotation: float
    contacts: list[ContactReport]
    unplanned_force: float
    max_effort: float
    samples: list[tuple[float, float, float]] = field(default_factory=list)
    wall_time: float = 0.0
    solution: Solution | None = None


def certified_torques(scenario: Scenario, urdf_xml: str | None = None
                      ) -> tuple[GraspSetup, GraspMaps, Solution, np.ndarray]:
    """
    Solve the scenario as the node solves it with gravity compensation.

    Returns:
        The setup (with g(q0) as torque offset), its maps, the certified solution
        and g(q0) [N m].
    """
    setup = GraspSetup.from_scenario(scenario, urdf_xml)
    g = gravity_torque(setup, setup.q, scenario.gravity)
    setup = dataclasses.replace(setup, torque_offset=g)
    maps = setup.maps()
    return setup, maps, solve(setup, maps=maps), g


def gravity_torque(setup: GraspSetup, q: np.ndarray, gravity: np.ndarray) -> np.ndarray:
    """g(q) of the actuated joints for a full configuration q [N m]."""
    return setup.hand.gravity_torques(q, gravity)


def hold(scenario: Scenario, settings: HoldSettings = HoldSettings(),
         sim_settings: SimSettings = SimSettings(), urdf_xml: str | None = None,
         tau: np.ndarray | None = None) -> HoldReport:
    """
    Run one hold episode of the scenario's certified torques.

    ``tau`` (actuator torques [N m], shape (m,)) replaces them when given: e.g. another
    method's, to see whether they hold too (the certified solution stays in the report).

    Raises:
        InputError: the scenario cannot be simulated (field named).
        ValueError: the scenario has no certified torques (infeasible or failed).
    """
    t_wall = time.perf_counter()
    setup, maps, sol, _ = certified_torques(scenario, urdf_xml)
    if not sol.optimal:
        raise ValueError(f'no certified torques to simulate: {sol.status} ({sol.message})')
    sim_model = build_model(scenario, sim_settings, urdf_xml, setup)
    hand = setup.hand
    hsim = HandSim(sim_model, setup.q[hand.idx_q], settings.kp, settings.kd)
    q_full = setup.q.copy()
    feedforward = settings.feedforward * (sol.tau if tau is None else np.asarray(tau))

    def command() -> np.ndarray:
        q_full[hand.idx_q] = hsim.q
        return feedforward + hand.gravity_torques(hand.complete(q_full), scenario.gravity)

    dt = sim_model.model.opt.timestep
    for _ in range(max(1, round(settings.settle / dt))):
        hsim.command = command()
        hsim.step()
    hsim.release()

    w = _watch(hsim, command, settings, maps.links, dt)
    contacts = []
    for i, (link, r) in enumerate(zip(maps.links, w.readings)):
        w_sim = wrench_in_frame(r, sim_model.base_rotation @ maps.rotations[i])
        w_pred = sol.wrenches[i]
        mu1, mu2 = scenario.friction.mu1, scenario.friction.mu2
        contacts.append(ContactReport(link, w_pred, w_sim, friction_usage(w_pred, mu1, mu2),
                                      friction_usage(w_sim, mu1, mu2), r.touching,
                                      maps.rotations[i]))
    drift, rotation = hsim.motion()
    t_end = hsim.time - hsim.release_time
    reason = _reason(w, settings, drift, rotation, t_end)
    return HoldReport(held=w.passed_at is None, reason=reason, time=t_end, drift=drift,
                      max_drift=w.max_drift, rotation=rotation, contacts=contacts,
                      unplanned_force=w.unplanned, max_effort=w.max_effort, samples=w.samples,
                      wall_time=time.perf_counter() - t_wall, solution=sol)


@dataclass
class _Watched:
    """
    What :func:`_watch` saw after the release.

    Attributes:
        samples: (time [s], drift [m], rotation [rad]) every sample period.
        lost: link -> when it first stopped touching the object [s].
        readings: the contact readings at the end, or at the last sample before the
            drift limit was passed.
        unplanned: force of other hand bodies on the object then [N].
        max_drift: largest displacement [m].
        max_effort: largest joint torque applied [N m].
        passed_at: when the drift passed its limit [s], or None.
        fallen: the drift at which the object counts as fallen [m].
    """

    samples: list[tuple[float, float, float]]
    lost: dict[str, float]
    readings: list
    unplanned: float
    max_drift: float = 0.0
    max_effort: float = 0.0
    passed_at: float | None = None
    fallen: float = 0.0


def _watch(hsim: HandSim, command, settings: HoldSettings, links: tuple[str, ...],
           dt: float) -> _Watched:
    """Step the released hand for the episode's duration (or until the object fell)."""
    readings, unplanned = hsim.readings()
    w = _Watched([], {}, readings, unplanned, fallen=max(20e-3, 10 * settings.drift_limit))
    per_sample = max(1, round(settings.sample_period / dt))
    n = round(settings.duration / dt)
    for k in range(1, n + 1):
        hsim.command = command()
        w.max_effort = max(w.max_effort, float(np.abs(hsim.effort()).max()))
        hsim.step()
        drift, rotation = hsim.motion()
        w.max_drift = max(w.max_drift, drift)
        t = hsim.time - hsim.release_time
        if drift > settings.drift_limit and w.passed_at is None:
            w.passed_at = t
        if k % per_sample == 0 or k == n or drift > w.fallen:
            w.samples.append((t, drift, rotation))
            now, now_unplanned = hsim.readings()
            for link, r in zip(links, now):
                if not r.touching:
                    w.lost.setdefault(link, t)
            if w.passed_at is None:
                w.readings, w.unplanned = now, now_unplanned
        if drift > w.fallen:
            break
    return w


def _reason(w: _Watched, settings: HoldSettings, drift: float, rotation: float,
            t_end: float) -> str:
    """Say why the object was held or not, in words."""
    limit_mm = settings.drift_limit * 1e3
    if w.passed_at is None:
        return (f'drift {drift * 1e3:.3f} mm, rotation {np.degrees(rotation):.3f} deg '
                f'after {t_end:.2f} s (limit {limit_mm:g} mm)')
    reason = f'drift passed {limit_mm:g} mm at t = {w.passed_at:.2f} s'
    reason += (f' and reached {w.max_drift * 1e3:.1f} mm (the object fell)'
               if w.max_drift > w.fallen else f', {drift * 1e3:.2f} mm at the end')
    if w.lost:
        first = min(w.lost, key=w.lost.get)
        reason += f'; contact lost first at {first} (t = {w.lost[first]:.2f} s)'
    return reason
