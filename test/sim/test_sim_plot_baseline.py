# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The plot's baseline (``grasp-torque-sim --plot-baseline``): real MuJoCo, the node's cycle.

The README's first command: the bundled Allegro ball 30% heavier than the scenario says
on a hand shaking at 1 g, 1 Hz along y, the driver's Kp 1. Its plot's default baseline
is the same node with the object loop off (the feedforward-only node): it drops the
ball, and the node with the loop holds it on the same rig, in simulated time.
"""

import os
import subprocess
import sys

from grasp_torque_opt.core.resources import find_config
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.ros.sim_compare import baseline_trace, node_controller
from grasp_torque_opt.sim.base_motion import BaseMotion, STANDARD_GRAVITY
from grasp_torque_opt.sim.episode import EpisodeSettings, run_episode, simulated
from grasp_torque_opt.sim.rig import Disturbances
import numpy as np
import pytest
from ros_harness import PROCESS_DOMAIN

SCENARIO = load_scenario(find_config('allegro_right.yaml'))
PARAMS = find_config('allegro_right_node.yaml')
README = EpisodeSettings(kp=1.0, duration=3.0, rate=250.0, mass_scale=1.3,
                         drift_limit=2e-3, disturbances=Disturbances(motion=BaseMotion(
                             shake_amplitude=STANDARD_GRAVITY, shake_frequency=1.0,
                             shake_axis=np.array([0.0, 1.0, 0.0]))))


def test_the_loop_off_baseline_drops_the_heavier_shaken_ball_the_loop_holds_it():
    base = baseline_trace(SCENARIO, README, kind='loop-off', params=PARAMS)
    # The trace stops when the ball has left the grasp (20 mm; its last row is the last
    # joint state before), before the run's end (at 2.7 s: the margin carries it so far).
    assert base[-1][0] < README.duration - 0.1 and base[-1][1] > 15e-3, base[-1]
    setup, rig = simulated(SCENARIO, README)
    held = run_episode(rig, node_controller(setup, SCENARIO, rig, inputs=True, params=PARAMS),
                       README)
    assert held.held and held.time == pytest.approx(README.duration, abs=2e-3)
    assert held.drift < 2e-3 and held.rotation < np.radians(2.0)


def test_a_baseline_needs_its_kind_and_the_loop_off_one_its_params_file():
    with pytest.raises(ValueError, match='baseline must be one of loop-off, scenario'):
        baseline_trace(SCENARIO, README, kind='other')
    with pytest.raises(ValueError, match='loop-off: needs the params file'):
        baseline_trace(SCENARIO, README, kind='loop-off')


def _sim(*args):
    env = dict(os.environ, ROS_DOMAIN_ID=str(PROCESS_DOMAIN),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    env.pop('MUJOCO_GL', None)
    return subprocess.run([sys.executable, '-m', 'grasp_torque_opt.ros.sim_driver', *args],
                          capture_output=True, text=True, timeout=180, env=env)


@pytest.mark.parametrize('choice, named', [(None, '(object loop off)'),
                                           ('scenario', '(scenario only)')])
def test_the_plot_line_names_the_baseline_it_ran(tmp_path, choice, named):
    plot = tmp_path / 'plot.png'
    done = _sim('--controller', 'preset', '--preset-level', '1.0', '--duration', '0.3',
                '--picture', str(tmp_path / 'grasp.png'), '--plot', str(plot),
                *(() if choice is None else ('--plot-baseline', choice)))
    assert done.returncode in (0, 1), done.stdout + done.stderr
    line = next(x for x in done.stdout.splitlines() if x.startswith('plot: '))
    assert named in line and plot.stat().st_size > 0, line


def test_an_unknown_plot_baseline_exits_2():
    done = _sim('--plot-baseline', 'preset')
    assert done.returncode == 2 and "--plot-baseline: invalid choice: 'preset'" in done.stderr
