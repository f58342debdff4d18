# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause
"""
Robustness benchmark (issue 24, item 6): the node and two baselines on a disturbed hand.

Usage: .venv/bin/python bench/robustness.py [--duration 3] [--gains 0.3,1] [--rate 250]
       [--out bench/results/robustness.json] [--node-inputs on|imu|off]
       [--margin K] [--imu-rate HZ] [--imu-latency S] [--effort-report applied|commanded]
       [--params FILE] [--object-loop on|off] [--grid issue24|targets|all]
       [--controllers node node-loop-off preset impedance] [--jobs N] [--smoke]

Not in CI. Every episode is grasp_torque_opt.sim.episode.run_episode() on the bundled
Allegro grasp (with --params, that file's scenario: config/g1_right_node.yaml runs the
G1's), in simulated time (the rig of grasp-torque-sim, without ROS): the
controller is asked at --rate (250 Hz) with the encoder's reading, the fingers press on the
pinned ball for 0.3 s, the ball is released and watched for --duration seconds. The
controllers:

- node: the node's own cycle (TorqueController, gravity compensation, ProxSuite with
  DAQP behind it), told only the scenario: the nominal mass, gravity and ball pose;
  with --node-inputs on, also the rig's palm IMU and measured efforts at each joint
  state (imu and effort_estimation on, as config/allegro_right_node.yaml turns them on);
  with --node-inputs imu, the IMU alone; --margin: its friction margin k;
  --effort-report commanded: the rig's driver reports the node's last command as effort
  (the Allegro V5's) and the node is told so (its stiffness the rig's Kp);
  with --params FILE (config/allegro_right_node.yaml: the bundled params), the node made
  from that params file as the node makes it (its margin, effort estimation, object loop;
  the IMU given when --node-inputs is not off and the file enables it; --margin unused);
  --object-loop on|off: the object loop (issue 32) turned on or off over the params;
- node-loop-off: the same node with the object loop off (object_loop.enabled false over
  the params): the feedforward-only node, what the bundled node was before issue 32;
- preset: fixed closing torques along the normals, one level tuned once per Kp on the
  nominal load (grasp_torque_opt.sim.baselines.tune_preset);
- impedance: the grasp pose commanded 5 mm inside the ball, position control at the
  driver's Kp.

The grid: base acceleration 0.5, 1 and 2 g along +-x, +-y, +-z, static and a 1 Hz
sinusoid of that peak; mass x0.7 and x1.3; the ball's centre 1, 3 and 5 mm off along
+-x, +-y, +-z; encoder noise 1 and 5 mrad; at each Kp. Held (the issue's target):
drift under 2 mm and rotation under 2 degrees at the end, the ball never further than
20 mm. Effort: the RMS applied joint torque after release (mean over the family's
episodes). --grid targets: issue 32's targets beyond that grid (families named "T ..."):
mass x0.5, x0.7, x1.3, x1.5; mass x1.2 and friction 30% low (the simulated mu 0.7 times
the scenario's), each under a 1 g, 1 Hz shake along x, y, z; Kp 0.1 with mass x1.3
(once, at its own Kp); --grid all: both. After the table, each node's cases not held
and by how much, and its effort against the bundled node's where both hold.
--smoke runs one case per family, Kp 1, 0.5 s: a check that it runs.

Reproducible: no ROS, no wall clock; the controllers are asked in simulated time and
the node's cycle runs in-process, untimed (no solver deadline), so a case's outcome is
the same on any load and with any --jobs (the figures to about 1e-6: floating point;
docs/simulation.md, "The grid of issue 32").
"""

from __future__ import annotations

import argparse
import multiprocessing
from pathlib import Path
import sys

import numpy as np

# bench/ on sys.path for its sibling modules (E402, I100 as in bench/physics.py).
sys.path.insert(0, str(Path(__file__).resolve().parent))
from cycle import machine, report  # noqa: E402, I100
from grasp_torque_opt.core.resources import find_config  # noqa: E402
from grasp_torque_opt.core.scenario import load_scenario, Scenario  # noqa: E402
from grasp_torque_opt.ros.node_process import scenario_of  # noqa: E402
from grasp_torque_opt.ros.sim_compare import node_controller  # noqa: E402
from grasp_torque_opt.sim.base_motion import BaseMotion, STANDARD_GRAVITY  # noqa: E402
from grasp_torque_opt.sim.baselines import Preset, Squeeze, tune_preset  # noqa: E402
from grasp_torque_opt.sim.episode import (  # noqa: E402
    EpisodeSettings,
    run_episode,
    simulated,
)
from grasp_torque_opt.sim.model import SimSettings  # noqa: E402
from grasp_torque_opt.sim.rig import Disturbances  # noqa: E402
from physics import commit  # noqa: E402

CONTROLLERS = ('node', 'node-loop-off', 'preset', 'impedance')
GRIDS = ('issue24', 'targets', 'all')
DIRECTIONS = {'+x': (1, 0, 0), '-x': (-1, 0, 0), '+y': (0, 1, 0), '-y': (0, -1, 0),
              '+z': (0, 0, 1), '-z': (0, 0, -1)}
HELD_DRIFT, HELD_ROTATION = 2e-3, np.radians(2.0)


def grid(smoke: bool, which: str = 'issue24') -> list[tuple[str, str, dict]]:
    """
    Return the cases: (family, label, EpisodeSettings fields).

    ``which``: issue 24's grid (59 cases), issue 32's targets (:func:`targets`) or both
    (``all``). A case's fields may also hold ``friction_scale`` (the simulated friction
    over the scenario's) and ``kp`` (the case's own driver stiffness).
    """
    if which == 'targets':
        return targets(smoke)
    if which == 'all':
        return grid(smoke) + targets(smoke)
    cases = [('nominal', 'nominal', {})]
    for g in ((1.0,) if smoke else (0.5, 1.0, 2.0)):
        for name, d in (list(DIRECTIONS.items())[:1] if smoke else DIRECTIONS.items()):
            a = g * STANDARD_GRAVITY * np.array(d, dtype=float)
            cases.append(('accel static', f'{g:g} g {name}', {'disturbances': Disturbances(
                motion=BaseMotion(accel=a))}))
            cases.append(('accel 1 Hz', f'{g:g} g {name}', {'disturbances': Disturbances(
                motion=BaseMotion(shake_amplitude=g * STANDARD_GRAVITY, shake_frequency=1.0,
                                  shake_axis=np.array(d, dtype=float)))}))
    for s in ((1.3,) if smoke else (0.7, 1.3)):
        cases.append(('mass', f'x{s:g}', {'mass_scale': s}))
    for mm in ((3.0,) if smoke else (1.0, 3.0, 5.0)):
        for name, d in (list(DIRECTIONS.items())[3:4] if smoke else DIRECTIONS.items()):
            cases.append(('offset', f'{mm:g} mm {name}',
                          {'object_offset': tuple(1e-3 * mm * np.array(d, dtype=float))}))
    for n in ((5.0,) if smoke else (1.0, 5.0)):
        cases.append(('noise', f'{n:g} mrad', {'disturbances': Disturbances(
            joint_noise=1e-3 * n, seed=1)}))
    return cases


def _shake(axis: str) -> Disturbances:
    """Return issue 32's shake: 1 g peak, 1 Hz, along a base axis."""
    return Disturbances(motion=BaseMotion(
        shake_amplitude=STANDARD_GRAVITY, shake_frequency=1.0,
        shake_axis=np.array(DIRECTIONS[f'+{axis}'], dtype=float)))


def targets(smoke: bool) -> list[tuple[str, str, dict]]:
    """
    Return issue 32's target cases beyond issue 24's grid (its 5 mm offsets are there).

    Mass x0.5 to x1.5; mass x1.2 and friction 30% low (mu 0.7 times the scenario's),
    each under the 1 g, 1 Hz shake along x, y and z; Kp 0.1 with mass x1.3 (at the
    case's own Kp, whatever the run's).
    """
    cases = [('T mass', f'x{s:g}', {'mass_scale': s})
             for s in ((1.3,) if smoke else (0.5, 0.7, 1.3, 1.5))]
    for axis in ('y',) if smoke else ('x', 'y', 'z'):
        cases.append(('T mass x1.2 + shake', axis, {'mass_scale': 1.2,
                                                    'disturbances': _shake(axis)}))
    for axis in ('y',) if smoke else ('x', 'y', 'z'):
        cases.append(('T friction 0.7 + shake', axis, {'friction_scale': 0.7,
                                                       'disturbances': _shake(axis)}))
    cases.append(('T Kp 0.1, mass x1.3', 'at Kp 0.1', {'kp': 0.1, 'mass_scale': 1.3}))
    return cases


def episode(scenario: Scenario, controller: str, settings: EpisodeSettings,
            preset_level: float, inputs: str = 'off', margin: float = 0.0,
            imu: tuple[float | None, float] = (None, 0.0), node: dict | None = None,
            sim: SimSettings | None = None) -> dict:
    """
    Run one episode; return its record (``inputs``: the node's IMU and efforts, on/imu/off).

    ``node``: ``params`` (a params file) and ``config`` (CycleConfig fields) for
    :func:`node_controller`; ``sim``: the simulation's settings (friction, ...).
    ``settings.effort_report``: what the rig reports.
    """
    setup, rig = simulated(scenario, settings, sim=sim or SimSettings())
    reference = None
    node = node or {}
    if controller in ('node', 'node-loop-off'):
        config = node.get('config') or {}
        if controller == 'node-loop-off':
            config = {**config, 'object_loop': False}
        command = node_controller(setup, scenario, rig, inputs != 'off', margin,
                                  efforts=None if node.get('params') else inputs == 'on',
                                  imu_rate=imu[0], imu_latency=imu[1],
                                  config=config or None, params=node.get('params'))
    elif controller == 'preset':
        command = Preset(setup, scenario.gravity, preset_level)
    else:
        command = Squeeze(setup, scenario.gravity)
        reference = command.reference
    r = run_episode(rig, command, settings, reference)
    held = (not r.fell and r.time >= settings.duration - 1e-9 and r.drift < HELD_DRIFT
            and r.rotation < HELD_ROTATION)
    return {'held': bool(held), 'drift_mm': 1e3 * r.drift, 'max_drift_mm': 1e3 * r.max_drift,
            'rotation_deg': float(np.degrees(r.rotation)), 'fell': r.fell,
            'effort_Nm': r.mean_effort, 'time_s': r.time}


def run(duration: float, gains: tuple[float, ...], smoke: bool, rate: float = 250.0,
        inputs: str = 'off', margin: float = 0.0,
        controllers: tuple[str, ...] = CONTROLLERS,
        imu: tuple[float | None, float] = (None, 0.0), effort_report: str = 'applied',
        node: dict | None = None, which: str = 'issue24', jobs: int = 1) -> dict:
    """Run the grid (``which``: :func:`grid`'s) for the controllers; return the record."""
    node = node or {}
    name = scenario_of(node['params']) if node.get('params') else 'allegro_right.yaml'
    scenario = load_scenario(find_config(name))
    out = {'scenario': name, 'duration_s': duration, 'gains': list(gains), 'rate_hz': rate,
           'rows': [], 'presets': {}, 'node_inputs': inputs, 'margin': margin,
           'effort_report': effort_report,
           'controllers': list(controllers), 'imu_rate_hz': imu[0], 'imu_latency_s': imu[1],
           'params': str(node.get('params') or ''), 'node_config': node.get('config') or {},
           'grid': which}
    levels: dict[float, float] = {}

    def level(kp: float) -> float:  # the preset tuned once per Kp, on the nominal load
        if kp not in levels:
            tuned = tune_preset(scenario, kp, 0.01, rate=rate)
            levels[kp] = tuned.level
            out['presets'][str(kp)] = {'level_N': tuned.level, 'drift_mm': 1e3 * tuned.drift}
        return levels[kp]

    tasks = []
    for kp in gains:
        for family, label, fields in grid(smoke, which):
            fields = dict(fields)
            scale = fields.pop('friction_scale', 1.0)
            own = fields.pop('kp', None)
            if own is not None and kp != gains[0]:
                continue  # a case at its own Kp runs once
            settings = EpisodeSettings(kp=kp if own is None else own, duration=duration,
                                       rate=rate, effort_report=effort_report, **fields)
            sim = SimSettings() if scale == 1.0 else SimSettings(
                mu_tangential=scale * scenario.friction.mu1,
                mu_torsional=scale * scenario.friction.mu2)
            head = {'kp': settings.kp, 'family': family, 'case': label}
            tasks += [(head, c, (scenario, c, settings, level(settings.kp), inputs, margin,
                                 imu, node, sim)) for c in controllers]
    # Each episode is independent and runs in simulated time: the processes change the
    # wall time only, not an outcome.
    with multiprocessing.get_context('fork').Pool(max(1, jobs)) as pool:
        records = pool.starmap(episode, [t[2] for t in tasks])
    for (head, c, _), record in zip(tasks, records):
        if not out['rows'] or out['rows'][-1]['case'] != head['case'] or \
                out['rows'][-1]['kp'] != head['kp'] or \
                out['rows'][-1]['family'] != head['family']:
            out['rows'].append(dict(head))
        out['rows'][-1][c] = record
    return out


def tables(r: dict) -> str:
    shown = r.get('controllers', CONTROLLERS)
    lines = [f"{r.get('scenario', 'allegro_right.yaml')}: "
             'held (drift < 2 mm and rotation < 2 deg at the end) and mean effort (RMS '
             f"joint torque after release) over {r['duration_s']:g} s, controllers asked at "
             f"{r['rate_hz']:g} Hz; node inputs (IMU, efforts) "
             f"{r.get('node_inputs')}, friction margin {r.get('margin', 0.0):g}"
             + (f", params {r['params']}" if r.get('params') else '')
             + (f", {r['node_config']}" if r.get('node_config') else '') + ', IMU '
             f"{r.get('imu_rate_hz') or r['rate_hz']:g} Hz "
             f"{1e3 * (r.get('imu_latency_s') or 0.0):g} ms late, efforts "
             f"{r.get('effort_report', 'applied')}; preset levels: "
             + ', '.join(f"Kp {k}: {p['level_N']:.2f} N" for k, p in r['presets'].items()),
             '', '| Kp | family | cases | ' + ' | '.join(
                 f'{c} held | {c} effort [N m]' for c in shown) + ' |',
             '|---|---|---|' + '---|---|' * len(shown)]
    keys = []
    for row in r['rows']:
        if (row['kp'], row['family']) not in keys:
            keys.append((row['kp'], row['family']))
    for kp, family in keys:
        rows = [x for x in r['rows'] if x['kp'] == kp and x['family'] == family]
        cells = []
        for c in shown:
            held = sum(x[c]['held'] for x in rows)
            cells.append(f'{held}/{len(rows)} | {np.mean([x[c]["effort_Nm"] for x in rows]):.4f}')
        lines.append(f'| {kp:g} | {family} | {len(rows)} | ' + ' | '.join(cells) + ' |')
    lines += misses(r['rows'], [c for c in shown if c.startswith('node')])
    if 'preset' not in shown or 'node' not in shown:
        return '\n'.join(lines)
    both = [x for x in r['rows'] if x['node']['held'] and x['preset']['held']]
    lower = sum(x['node']['effort_Nm'] < x['preset']['effort_Nm'] for x in both)
    lines += ['', f'Where node and preset both hold ({len(both)} cases), the node uses less '
              f'effort in {lower}.']
    return '\n'.join(lines)


def misses(rows: list[dict], nodes: list[str]) -> list[str]:
    """Return, per node controller, the cases it did not hold and by how much."""
    lines = []
    for c in nodes:
        lost = [x for x in rows if not x[c]['held']]
        lines += ['', f'{c}: not held in {len(lost)} of {len(rows)}' + (':' if lost else '.')]
        lines += [f"- Kp {x['kp']:g}, {x['family']} {x['case']}: " + (
            f"fell at {x[c].get('time_s', 0.0):.2f} s" if x[c]['fell'] else
            f"drift {x[c]['drift_mm']:.2f} mm, rotation {x[c]['rotation_deg']:.2f} deg")
            for x in lost]
        if c != 'node' and rows and 'node' in rows[0]:
            both = [x for x in rows if x['node']['held'] and x[c]['held']]
            ratio = [x['node']['effort_Nm'] / x[c]['effort_Nm'] for x in both]
            if ratio:
                lines.append(f'Where node and {c} both hold ({len(both)} cases), the '
                             f"node's effort is {np.mean(ratio):.2f} times {c}'s on average, "
                             f'at most {np.max(ratio):.2f} times.')
    return lines


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument('--duration', type=float, default=3.0, help='simulated hold [s]')
    p.add_argument('--gains', default='0.3,1', help='driver Kp values [N m/rad]')
    p.add_argument('--rate', type=float, default=250.0,
                   help="how often the controllers are asked [Hz] (grasp-torque-sim's joint "
                        'state rate)')
    p.add_argument('--out', type=Path, default=Path('bench/results/robustness.json'))
    p.add_argument('--imu-rate', type=float, default=None,
                   help='the IMU sampled at this rate [Hz] (default: at every joint state)')
    p.add_argument('--imu-latency', type=float, default=0.0,
                   help='the IMU delivered this late [s]')
    p.add_argument('--margin', type=float, default=0.0, help="the node's friction margin k")
    p.add_argument('--controllers', nargs='+', default=list(CONTROLLERS), choices=CONTROLLERS)
    p.add_argument('--node-inputs', choices=('on', 'imu', 'off'), default='off',
                   help="the node's IMU and effort estimation (issue 24): on, as the "
                        'bundled params, or off (the scenario only)')
    p.add_argument('--effort-report', choices=('applied', 'commanded'), default='applied',
                   help="what the driver's joint_states effort is (the node is told)")
    p.add_argument('--params', type=Path, default=None,
                   help='the node made from this params file, as the node makes it (e.g. '
                        'config/allegro_right_node.yaml: the bundled params)')
    p.add_argument('--object-loop', choices=('on', 'off'), default=None,
                   help="the node's object loop (issue 32) on or off, over the params")
    p.add_argument('--grid', choices=GRIDS, default='issue24',
                   help="the cases: issue 24's grid (59), issue 32's targets beyond it, or all")
    p.add_argument('--jobs', type=int, default=1,
                   help='episodes run in this many processes (the outcomes are the same)')
    p.add_argument('--smoke', action='store_true',
                   help='one case per family, Kp 1, 0.5 s: that it runs')
    a = p.parse_args()
    gains = (1.0,) if a.smoke else tuple(float(k) for k in a.gains.split(','))
    duration = 0.5 if a.smoke else a.duration
    node = {'params': a.params, 'config': None if a.object_loop is None
            else {'object_loop': a.object_loop == 'on'}}
    started = commit()  # the code that runs is the one at the start
    r = run(duration, gains, a.smoke, a.rate, a.node_inputs, a.margin, tuple(a.controllers),
            (a.imu_rate, a.imu_latency), a.effort_report, node, a.grid, a.jobs)
    r['machine'], r['commit'], r['smoke'] = machine(), started, a.smoke
    report(r, tables(r), None if a.smoke else a.out,
           f"commit {r['commit']}, {len(r['rows']) * len(a.controllers)} episodes"
           + (' (smoke run)' if a.smoke else ''))
    return 0


if __name__ == '__main__':
    sys.exit(main())
