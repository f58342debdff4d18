# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause
"""
The load from efforts against a slip and against its own command (issue 32, item 4).

Usage: .venv/bin/python bench/effort_gate.py [--hold 60] [--gains 0.3,1]

Not in CI. In simulated time, without ROS: the node's cycle as bench/robustness.py runs
it (IMU and efforts on, friction margin 0.31) on the rig of grasp-torque-sim.

- slip: the ball 5 mm off its place along each base direction, 1 s after release, the
  gate as the parameters' defaults set it and opened (its limits beyond anything the
  rig does: the node before issue 32): the correction along gravity at release and
  its least value [N], the drift [mm] and rotation [deg] at the end.
- still: a driver that reports the node's last command as effort (the Allegro V5's) on
  a still hand for --hold seconds, the node told so (effort_report commanded, its
  stiffness the rig's Kp) or told the efforts are applied torques (the node before):
  the largest |correction| and |estimate - weight| over the weight after release, when
  the correction first passed 2% of the weight, the drift at the end.
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys

import numpy as np

# bench/ on sys.path for its sibling modules (E402, I100 as in bench/physics.py).
sys.path.insert(0, str(Path(__file__).resolve().parent))
from cycle import machine, machine_line  # noqa: E402, I100
from grasp_torque_opt.core.resources import find_config  # noqa: E402
from grasp_torque_opt.core.scenario import load_scenario  # noqa: E402
from grasp_torque_opt.ros.sim_compare import effort_episode  # noqa: E402
from grasp_torque_opt.sim.episode import EpisodeSettings  # noqa: E402
from physics import commit  # noqa: E402

SCENARIO = load_scenario(find_config('allegro_right.yaml'))
WEIGHT = SCENARIO.object.mass * float(np.linalg.norm(SCENARIO.gravity))
DIRECTIONS = {'+x': (1, 0, 0), '-x': (-1, 0, 0), '+y': (0, 1, 0), '-y': (0, -1, 0),
              '+z': (0, 0, 1), '-z': (0, 0, -1)}


def episode(settings: EpisodeSettings, gate: bool = True, report: str | None = None):
    """Run the node's cycle on the rig (sim_compare.effort_episode)."""
    return effort_episode(SCENARIO, settings, gate, report)


def slip(kp: float) -> None:
    print(f'slip, Kp {kp:g}: | offset | gate | b at release [N] | least b [N] | drift [mm] '
          '| rotation [deg] |')
    for name, d in DIRECTIONS.items():
        settings = EpisodeSettings(kp=kp, duration=1.0,
                                   object_offset=tuple(5e-3 * np.array(d, dtype=float)))
        for gate in (True, False):
            r, rows = episode(settings, gate)
            at = rows[np.searchsorted(rows[:, 0], 0.0, side='right') - 1, 1]  # last pinned
            print(f"| 5 mm {name} | {'on' if gate else 'opened'} | {at:+.3f} | "
                  f'{rows[:, 1].min():+.3f} | {1e3 * r.drift:.2f} | '
                  f'{np.degrees(r.rotation):.2f} |', flush=True)


def still(kp: float, hold: float) -> None:
    print(f'still, Kp {kp:g}, {hold:g} s: | told | max |b|/W | max |est - W|/W | b past 2% '
          'at [s] | drift [mm] |')
    for told in ('commanded', 'applied'):
        settings = EpisodeSettings(kp=kp, duration=hold, effort_report='commanded')
        r, rows = episode(settings, report=told)
        after = rows[rows[:, 0] > 0.0]
        est = after[np.isfinite(after[:, 2]), 2]
        past = np.nonzero(np.abs(after[:, 1]) > 0.02 * WEIGHT)[0]
        print(f'| {told} | {np.abs(after[:, 1]).max() / WEIGHT:.4f} | '
              f'{np.abs(est - WEIGHT).max() / WEIGHT if len(est) else float("nan"):.4f} | '
              f"{f'{after[past[0], 0]:.3f}' if len(past) else 'never'} | {1e3 * r.drift:.3f} |",
              flush=True)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    p.add_argument('--hold', type=float, default=60.0, help='the still hold [s]')
    p.add_argument('--gains', default='0.3,1', help='driver Kp values [N m/rad]')
    a = p.parse_args()
    print(machine_line(machine()) + f'; commit {commit()}')
    for kp in (float(k) for k in a.gains.split(',')):
        slip(kp)
        still(kp, a.hold)
    return 0


if __name__ == '__main__':
    sys.exit(main())
