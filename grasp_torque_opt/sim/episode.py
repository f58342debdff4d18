# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
One episode on the rig without ROS: any controller, the disturbances, held or not.

What ``grasp-torque-sim`` does over ROS, in simulated time: a controller is asked
for a command at the joint state rate from the encoder's reading and the command
is held between (as the effort controller holds it); the fingers press on the
pinned object for ``settle`` seconds; the object is released and watched. The
controller is a callable, so that the node's own cycle (which this family may not
import, docs/architecture.md) or a baseline (:mod:`~grasp_torque_opt.sim.baselines`)
can drive the same rig.
"""

from __future__ import annotations

from collections.abc import Callable
import dataclasses
from dataclasses import dataclass, field

from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.scenario import Scenario
from grasp_torque_opt.sim.model import build_model, SimSettings
from grasp_torque_opt.sim.rig import Disturbances, EFFORT_REPORTS, RigSim
import numpy as np

#: A controller: the encoder's reading [rad] -> the command [N m] (None: keep the last).
Controller = Callable[[np.ndarray], 'np.ndarray | None']


@dataclass(frozen=True)
class EpisodeSettings:
    """
    One episode.

    Attributes:
        kp: the driver's joint stiffness [N m/rad].
        kd: the driver's joint damping [N m s/rad].
        duration: simulated time after release [s].
        settle: simulated time the fingers press on the pinned object [s].
        rate: how often the controller is asked (the joint state rate) [Hz].
        drift_limit: held while the object moves less than this [m].
        disturbances: base motion and encoder noise.
        mass_scale: the simulated object's mass over the scenario's [-].
        object_offset: the simulated object's centre minus the scenario's, base frame [m].
        object_force: a constant force on the object's centre from release on, base
            axes [N] (the controller is not told).
        effort_report: what the driver's joint states' effort is, ``applied`` or
            ``commanded`` (:attr:`~grasp_torque_opt.sim.rig.RigSim.effort_report`).
    """

    kp: float = 1.0
    kd: float = 0.01
    duration: float = 2.0
    settle: float = 0.3
    rate: float = 250.0
    drift_limit: float = 1e-3
    disturbances: Disturbances = field(default_factory=Disturbances)
    mass_scale: float = 1.0
    object_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    object_force: tuple[float, float, float] = (0.0, 0.0, 0.0)
    effort_report: str = 'applied'

    def __post_init__(self) -> None:
        """Refuse an effort report that is neither applied nor commanded."""
        if self.effort_report not in EFFORT_REPORTS:
            raise ValueError(f'effort_report must be one of {", ".join(EFFORT_REPORTS)}, got '
                             f'{self.effort_report!r}')


@dataclass(frozen=True)
class EpisodeReport:
    """
    What an episode did.

    Attributes:
        held: the object moved less than the drift limit all the time.
        passed_at: when the drift passed the limit, after release [s] (None if held).
        max_drift: largest drift [m].
        drift: drift at the end [m].
        rotation: rotation at the end [rad].
        time: simulated time after release [s] (shorter once the object fell).
        mean_effort: RMS applied joint torque since release [N m].
        max_rotation: largest rotation since release [rad].
    """

    held: bool
    passed_at: float | None
    max_drift: float
    drift: float
    rotation: float
    time: float
    mean_effort: float
    max_rotation: float = 0.0

    @property
    def fell(self) -> bool:
        """Return whether the object left the grasp (more than 20 mm)."""
        return self.max_drift > 20e-3


def simulated(scenario: Scenario, settings: EpisodeSettings, setup: GraspSetup | None = None,
              sim: SimSettings = SimSettings()) -> tuple[GraspSetup, RigSim]:
    """
    Build the rig for a scenario, with the object as it really is.

    Its mass scaled and its centre offset from the scenario's; the hand at the
    scenario's grasp configuration.
    """
    setup = setup or GraspSetup.from_scenario(scenario)
    true_object = dataclasses.replace(
        scenario.object, position=np.asarray(scenario.object.position)
        + np.asarray(settings.object_offset, dtype=float))
    truth = dataclasses.replace(scenario, object=true_object)
    sim = dataclasses.replace(sim, mass=settings.mass_scale * scenario.object.mass)
    rig = RigSim(build_model(truth, sim), setup.q[setup.hand.idx_q], settings.kp, settings.kd,
                 settings.disturbances, setup.hand.base_frame)
    rig.object_force = np.asarray(settings.object_force, dtype=float)
    rig.effort_report = settings.effort_report
    return setup, rig


def run_episode(rig: RigSim, controller: Controller, settings: EpisodeSettings,
                reference: Callable[[np.ndarray], np.ndarray] | None = None,
                trace: list | None = None) -> EpisodeReport:
    """
    Drive the rig with a controller for one episode (settle, release, hold).

    Args:
        rig: a fresh rig (:func:`simulated`).
        controller: asked at ``settings.rate`` with the encoder's reading.
        settings: the episode.
        reference: the driver's impedance reference, from the one it has (the grasp
            configuration before the settling, the settled one after release); None:
            those (a driver in effort mode).
        trace: if given, a row (time since release [s], drift [m], RMS of the applied
            joint torques [N m]) is appended each time the controller is asked after
            release.
    """
    dt = rig.model.opt.timestep
    every = max(1, round(1.0 / (settings.rate * dt)))
    fallen = max(20e-3, 10 * settings.drift_limit)

    turned = [0.0]

    def steps(n: int, watch: bool) -> tuple[float | None, float]:
        passed, most = None, 0.0
        for k in range(n):
            if k % every == 0:
                command = controller(rig.reading)
                if command is not None:
                    rig.command = np.asarray(command, dtype=float)
            rig.step()
            if watch:
                drift, rotation = rig.motion()
                turned[0] = max(turned[0], rotation)
                if trace is not None and k % every == 0:
                    applied = rig.effort()
                    trace.append((rig.time - rig.release_time, drift,
                                  float(np.sqrt(np.mean(applied ** 2)))))
                most = max(most, drift)
                if drift > settings.drift_limit and passed is None:
                    passed = rig.time - rig.release_time
                if drift > fallen:
                    break
        return passed, most

    if reference is not None:
        rig.q_ref = np.asarray(reference(rig.q_ref), dtype=float)
    steps(max(1, round(settings.settle / dt)), False)
    rig.release()
    if reference is not None:
        rig.q_ref = np.asarray(reference(rig.q_ref), dtype=float)
    passed, most = steps(round(settings.duration / dt), True)
    drift, rotation = rig.motion()
    return EpisodeReport(held=passed is None, passed_at=passed, max_drift=most, drift=drift,
                         rotation=rotation, time=rig.time - rig.release_time,
                         mean_effort=rig.mean_effort(), max_rotation=turned[0])
