# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The load from efforts on the simulated hand: a slip is no lighter load, an echo no load.

In simulated time, without ROS: the node's cycle as bench/robustness.py runs it (IMU and
efforts on, the bundled params' friction margin 0.31) on the rig at Kp 0.3.

- A ball 5 mm off its place is touched elsewhere than the contacts the estimate inverts
  through, and turns once released: ungated, its efforts read as a lighter load and the
  correction goes to its bound (-0.74 N); gated on the fingertips' agreement with the
  object, it is not integrated. Each case runs with the gate opened too (its limits
  beyond anything the rig does), where the ball must be read lighter: so the test can fail.
- A driver that reports the node's own last command (the Allegro V5's): told so
  (effort_report commanded, its stiffness the rig's Kp), the estimate is the ball's
  weight within 2% (analytic: m |g|) over a long hold and the correction stays within
  2% of it; told the efforts are applied torques (the node before the parameter), the
  correction runs away.
"""

import dataclasses

from grasp_torque_opt.control.effort_load import applied_torque
from grasp_torque_opt.core.resources import find_config
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.ros.sim_compare import effort_episode
from grasp_torque_opt.sim.episode import EpisodeSettings, simulated
import numpy as np
import pytest

SCENARIO = load_scenario(find_config('allegro_right.yaml'))
WEIGHT = SCENARIO.object.mass * float(np.linalg.norm(SCENARIO.gravity))  # 1.4715 N
BOUND = 0.5 * WEIGHT  # effort_estimation.max_load_ratio's default
#: A hold of the still hand [s]: 20 s simulated runs in about 10 to 20 s here; the
#: 60 s run of the issue's target is docs/simulation.md's (bench/effort_gate.py).
LONG_HOLD = 20.0


def episode(settings: EpisodeSettings, gate: bool = True, report: str | None = None):
    """Run the node's cycle on the rig (sim_compare.effort_episode)."""
    return effort_episode(SCENARIO, settings, gate, report)


@pytest.mark.parametrize('offset', [(0.0, 0.0, 5e-3), (5e-3, 0.0, 0.0)])
def test_a_ball_off_its_place_is_not_read_as_a_lighter_load(offset):
    settings = EpisodeSettings(kp=0.3, duration=1.0, object_offset=offset)
    held, rows = episode(settings)
    assert rows[:, 1].min() > -0.05 * WEIGHT, rows[:, 1].min()
    assert held.drift < 2e-3 and held.rotation < np.radians(2.0), held
    ungated, rows = episode(settings, gate=False)
    assert rows[:, 1].min() < -0.7 * BOUND, rows[:, 1].min()  # given way: a lighter load
    assert ungated.rotation > np.radians(2.0), ungated


def test_an_honest_commanded_driver_is_read_within_two_percent_on_a_long_hold():
    settings = EpisodeSettings(kp=0.3, duration=LONG_HOLD, effort_report='commanded')
    held, rows = episode(settings)
    assert held.time >= LONG_HOLD - 1e-9 and held.drift < 1e-3, held
    after = rows[rows[:, 0] > 0.0]
    assert np.abs(after[:, 1]).max() < 0.02 * WEIGHT, np.abs(after[:, 1]).max()
    estimated = after[np.isfinite(after[:, 2]), 2]
    assert len(estimated) > 0.9 * len(after)  # the gate open nearly all along
    assert np.abs(estimated - WEIGHT).max() < 0.02 * WEIGHT, estimated
    # Told the echo is the applied torque: the integral has no feedback and runs away.
    short = dataclasses.replace(settings, duration=2.0)
    _, rows = episode(short, report='applied')
    assert rows[-1, 1] > 0.2 * WEIGHT, rows[-1, 1]


def test_the_rig_reports_the_command_or_the_applied_torque():
    """The rig's applied torque is the command plus the impedance around q_ref (still hand)."""
    settings = EpisodeSettings(kp=0.3, effort_report='commanded')
    setup, rig = simulated(SCENARIO, settings)
    rig.command = np.full(rig.q.shape, 0.05)
    rig.step(20)
    np.testing.assert_allclose(rig.reported_effort(), rig.command)
    np.testing.assert_allclose(
        applied_torque(rig.reported_effort(), 'commanded', 0.3, rig.q_ref, rig.reading)
        - rig.kd * rig.qdot, rig.effort(), atol=1e-12)
    rig.effort_report = 'applied'
    np.testing.assert_allclose(rig.reported_effort(), rig.effort())
    with pytest.raises(ValueError, match='effort_report must be one of applied, commanded'):
        EpisodeSettings(effort_report='current')
