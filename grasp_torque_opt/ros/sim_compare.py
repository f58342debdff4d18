# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The node's cycle on the rig without ROS: the baseline beside a run, and the benchmark's node.

``grasp-torque-sim`` runs the node over ROS; beside it, for the plot, the same
disturbances on a fresh rig in simulated time with the node's own cycle as a baseline:
by default made from the same params file with the object loop off (the feedforward-only
node, what the node was before issue 32), or told only the scenario (no IMU, no efforts:
what the node was before issue 24).
bench/robustness.py drives every episode of its grid through :func:`node_controller`.
"""

from __future__ import annotations

import collections
import dataclasses
from pathlib import Path
from typing import Any

from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.control.inputs.imu import ImuReading
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.parameters.generated import CycleConfig, Params
from grasp_torque_opt.control.parameters.schema import SCHEMA
from grasp_torque_opt.control.parameters.snapshot import params_from
from grasp_torque_opt.core.bounded_yaml import BoundedLoader
from grasp_torque_opt.core.object_from_hand import ObjectFromHand
from grasp_torque_opt.core.object_geometry import object_pose
from grasp_torque_opt.core.scenario import Scenario
from grasp_torque_opt.native.loader import fast_cycle
from grasp_torque_opt.ros.node.controllers import configure
from grasp_torque_opt.ros.node.grasp_source import load_of_gravity, weight_of
from grasp_torque_opt.ros.node.parameters import scenario_defaults
from grasp_torque_opt.sim.episode import EpisodeSettings, run_episode, simulated
import yaml

#: The cycle's budget and joint state timeout as lockstep sets them (the schema's largest,
#: ros/sim_driver.LOCKSTEP_PARAMETERS): simulated time is not timed, so no solver is cut
#: by the wall clock, and a cycle slowed by a loaded machine does not age its joint state
#: (the budget is the smaller of the two: a joint_state_timeout of 0.05 s cut the G1's
#: solves on a busy 2-core machine and dropped its ball).
UNTIMED = {'cycle_budget': 1.0, 'joint_state_timeout': 10.0}


def params_file(path: str | Path, scenario: Scenario, setup) -> Params:
    """
    Read a node's params file (``/**: ros__parameters:``) as the node would take it.

    The schema's defaults, then the scenario's (:func:`scenario_defaults`), then the
    file's values by dotted name (every node key's ``ros__parameters``), each checked by
    the schema; the file's ``scenario`` is not read (the caller's is used).
    """
    with open(path, encoding='utf-8') as f:
        doc = yaml.load(f, Loader=BoundedLoader) or {}
    values = {**SCHEMA.defaults(), **scenario_defaults(scenario, setup)}

    def flat(prefix: str, body: Any) -> None:
        for key, value in body.items():
            if isinstance(value, dict):
                flat(f'{prefix}{key}.', value)
            elif f'{prefix}{key}' != 'scenario':
                SCHEMA.check(f'{prefix}{key}', value)
                values[f'{prefix}{key}'] = value
    for body in doc.values():
        flat('', (body or {}).get('ros__parameters', {}))
    return params_from(values)


def _controller(setup, scenario: Scenario, rig, inputs: bool, margin: float,
                efforts: bool | None, effort_report: str | None, over: dict,
                params: str | Path | None) -> tuple[TorqueController, bool, bool]:
    """Make :func:`node_controller`'s cycle; return it, whether the IMU and efforts go in."""
    report = effort_report or (rig.effort_report if rig is not None else 'applied')
    told = {'effort_report': report,
            'effort_driver_stiffness': rig.kp if rig is not None else 0.0}
    if params is not None:
        p = params_file(params, scenario, setup)
        ctrl = configure(None, setup, p, obj=scenario.object)
        if effort_report is not None or report != 'applied':
            over = {**told, **over}
        ctrl.config = dataclasses.replace(ctrl.config, **UNTIMED, **over)
        inputs, efforts = inputs and p.imu.enabled, ctrl.config.effort_estimation
    else:
        efforts = inputs if efforts is None else efforts
        setup = dataclasses.replace(setup, friction=dataclasses.replace(setup.friction,
                                                                        margin=margin))
        ctrl = TorqueController(setup, CycleConfig(
            gravity_compensation=True, gravity=tuple(float(x) for x in scenario.gravity),
            effort_estimation=efforts, **{**UNTIMED, **told, **over}), fallback='daqp')
    ctrl.untimed = True  # simulated time: the outcome depends on no wall clock
    ctrl.load_of_gravity = load_of_gravity(scenario)
    ctrl.solving.weight = weight_of(scenario)
    if scenario.object is not None:
        ctrl.solving.hand_object = ObjectFromHand(
            setup.hand, setup.contacts, setup.q,
            object_pose(scenario.object.position, scenario.object.rpy), module=fast_cycle)
    return ctrl, inputs, efforts


def node_controller(setup, scenario: Scenario, rig=None, inputs: bool = False,
                    margin: float = 0.0, efforts: bool | None = None,
                    imu_rate: float | None = None, imu_latency: float = 0.0,
                    commands: dict | None = None, effort_report: str | None = None,
                    config: dict | None = None, params: str | Path | None = None):
    """
    Return the node's cycle as a controller: a joint state in, its command out.

    Configured as config/allegro_right_node.yaml configures the node: gravity
    compensation with the scenario's gravity (the parameter's default from the
    scenario), DAQP as the fallback; the budget generous (:data:`UNTIMED`).
    With ``inputs`` (issue 24's inputs on, as the bundled params turn them on): the rig's
    palm IMU and its measured efforts (effort_estimation) are given to the cycle at each
    joint state. ``efforts``: the effort estimation alone on or off (None: as ``inputs``).
    ``margin``: the friction margin k. ``imu_rate`` [Hz] (None: at every joint state)
    and ``imu_latency`` [s]: the IMU sampled at that rate and delivered that late (the
    readings are kept at every physics step asked, the one of ``imu_latency`` ago given).
    ``commands``: the command interface's CycleConfig fields (``command_interface``,
    ``position_stiffness``, ...; None: effort); the cycle's result, its ``output`` in the
    driver's units, is ``command.controller.last``.
    The efforts are what the rig's driver reports (:meth:`RigSim.reported_effort
    <grasp_torque_opt.sim.rig.RigSim.reported_effort>`); ``effort_report``: what the
    cycle is told they are (None: what they are), with ``commanded`` the driver's
    stiffness the rig's Kp and its reference the scenario's grasp (the default).
    The fingertips' estimate of the object is placed as the node places it (the gate).
    ``config``: further CycleConfig fields by name (the object loop's, e.g.
    ``{'object_loop': True}``), over those. The cycle is ``untimed``
    (:class:`~grasp_torque_opt.control.controller.TorqueController`): its solvers get no
    deadline and its wall time decides nothing, so that an episode's outcome is the same
    on any machine load (a deadline made ProxSuite stop by its own timing, in chunks that
    moved a falling ball's end by 0.01 mm between two runs).

    With ``params`` (a node's params file, config/allegro_right_node.yaml), the controller
    is the node's own, made from the file as the node makes it (:func:`params_file`,
    :func:`~grasp_torque_opt.ros.node.controllers.configure`): ``margin`` and
    ``efforts`` are the file's, the IMU is given if ``inputs`` and the file's
    ``imu.enabled``; only the cycle's budget and joint state timeout are lockstep's
    (:data:`UNTIMED`: simulated time is not timed), and ``config`` still goes over the
    file's.
    """
    ctrl, inputs, efforts = _controller(setup, scenario, rig, inputs, margin, efforts,
                                        effort_report, {**(commands or {}), **(config or {})},
                                        params)
    names = list(setup.hand.joints)
    clock = {'t': 0.0, 'imu': -1.0}
    readings: collections.deque = collections.deque()

    def command(reading):
        # The simulated time (the estimate's filters run on it); without a rig, any
        # increasing time: the inputs are always fresh here.
        clock['t'] = 1.0 + rig.time if rig is not None else clock['t'] + 1e-3
        measured = None
        if inputs:
            readings.append((clock['t'], *rig.imu()))
            while len(readings) > 1 and readings[1][0] <= clock['t'] - imu_latency:
                readings.popleft()
            sampled, force, omega = readings[0]
            due = imu_rate is None or sampled - clock['imu'] >= 1.0 / imu_rate - 1e-9
            if sampled <= clock['t'] - imu_latency + 1e-12 and due:
                clock['imu'] = sampled
                ctrl.take('imu', ImuReading('', force, omega), clock['t'])
        if efforts:
            measured = rig.reported_effort().tolist()
        ctrl.take('joint_states', JointStateReading(names, reading.tolist(), efforts=measured),
                  clock['t'], 0.0, None)
        return ctrl.cycle(clock['t']).command
    command.controller = ctrl
    return command


#: The plot's baselines (``grasp-torque-sim --plot-baseline``): the node on its params
#: file with the object loop off (the feedforward-only node: the scenario's load, the
#: IMU's, no feedback from the object's motion), or the node told only the scenario.
BASELINES = ('loop-off', 'scenario')


def baseline_trace(scenario: Scenario, settings: EpisodeSettings, sim=None,
                   kind: str = 'scenario', params: str | Path | None = None) -> list:
    """
    Run a baseline node on a fresh rig with the same disturbances; return its trace.

    ``kind``: ``scenario``, the node told only the scenario (no IMU, no efforts, friction
    margin 0); ``loop-off``, the node made from ``params`` as the node makes it (its
    margin, the IMU when the file enables it, effort estimation as the file says) with
    ``object_loop.enabled`` false. Rows of (time since release [s], drift [m], RMS
    applied joint torque [N m]), as :func:`~grasp_torque_opt.sim.episode.run_episode`
    records them.
    """
    if kind not in BASELINES:
        raise ValueError(f'baseline must be one of {", ".join(BASELINES)}, got {kind!r}')
    if kind == 'loop-off' and params is None:
        raise ValueError('baseline loop-off: needs the params file')
    kw = {} if sim is None else {'sim': sim}
    setup, rig = simulated(scenario, settings, **kw)
    trace: list = []
    if kind == 'scenario':
        command = node_controller(setup, scenario, rig, inputs=False)
    else:
        command = node_controller(setup, scenario, rig, inputs=True, params=params,
                                  config={'object_loop': False})
    run_episode(rig, command, settings, trace=trace)
    return trace


def effort_episode(scenario: Scenario, settings: EpisodeSettings, gate: bool = True,
                   report: str | None = None, margin: float = 0.31):
    """
    Run the node's cycle with the load from efforts on the rig; trace its correction.

    The bench (bench/effort_gate.py) and the tests of the effort gate run this one
    episode: the IMU and efforts on, the bundled params' friction margin; ``gate`` False
    opens the gate (its limits beyond anything the rig does: the node before issue 32).

    Returns:
        The episode's outcome and rows (time after release [s], correction x [N],
        estimate x [N] or NaN).
    """
    import numpy as np

    setup, rig = simulated(scenario, settings)
    command = node_controller(setup, scenario, rig, inputs=True, margin=margin, efforts=True,
                              effort_report=report)
    ctrl = command.controller
    if not gate:
        ctrl.config = dataclasses.replace(ctrl.config, effort_max_residual=0.1,
                                          effort_max_object_speed=1.0)
    rows = []

    def recorded(reading):
        out = command(reading)
        est = ctrl.solving.effort_load
        rows.append((rig.time - (rig.release_time or rig.time), float(est.correction[0]),
                     np.nan if est.estimate is None else float(est.estimate[0])))
        return out
    return run_episode(rig, recorded, settings), np.array(rows)
