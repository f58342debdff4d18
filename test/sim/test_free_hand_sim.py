# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Finger gravity compensation in physics: with no object, g(q) keeps the fingers in place.

Zero torques let them sag (issue 34's target: within 1 mm for 3 s).

The simulated Allegro, palm down (the scenario's gravity +x), the driver's joint
impedance at Kp 0.3 around the start (what a driver in effort mode keeps), the node's
own cycle with ``hold_object`` false asked at 250 Hz in simulated time.
"""

from conftest import ALLEGRO
from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.parameters.generated import CycleConfig
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.sim.episode import EpisodeSettings, simulated
import numpy as np
import pytest

DURATION, RATE = 3.0, 250.0


def tips_moved(compensate: bool, kp: float = 0.3) -> float:
    """Return the largest move of a contact link from its start over the run [m]."""
    scenario = load_scenario(ALLEGRO)
    setup, rig = simulated(scenario, EpisodeSettings(kp=kp))
    rig.remove_object()
    config = CycleConfig(gravity_compensation=compensate, hold_object=False, cycle_budget=1.0,
                         gravity=tuple(float(v) for v in scenario.gravity))
    ctrl = TorqueController(setup, config)
    names = list(setup.hand.joints)
    bodies = rig.sim.contact_bodies
    start = rig.data.xpos[list(bodies)].copy()
    every = round(1.0 / (RATE * rig.model.opt.timestep))
    most = 0.0
    for k in range(round(DURATION / rig.model.opt.timestep)):
        if k % every == 0:
            ctrl.take('joint_states', JointStateReading(names, rig.reading.tolist()), rig.time)
            result = ctrl.cycle(rig.time)
            assert result.kind == 'solution', result.fault
            rig.command = result.command
        rig.step()
        most = max(most, float(np.linalg.norm(rig.data.xpos[list(bodies)] - start,
                                              axis=1).max()))
    return most


@pytest.mark.parametrize('kp', [0.3, 1.0])
def test_the_fingers_stay_where_they_are_put_and_sag_without_compensation(kp):
    assert tips_moved(True, kp) < 1e-3
    assert tips_moved(False, kp) > 1e-3  # the same run with zero torques: they sag
