# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Physics benchmark: whether the simulated Allegro holds the ball, and with what margin.

Usage: .venv/bin/python bench/physics.py [--duration 2] [--kd 0.01]
       [--out bench/results/physics.json]

Not in CI. Every episode is grasp_torque_opt.sim.hold.hold(): the scenario solved
as the node solves it (tau-QP, g(q0) as torque offset, certified), the torques
plus g(q) at the measured configuration and a joint impedance applied in MuJoCo
for ``--duration`` simulated seconds after the fingers settled on the pinned ball;
held = the ball moved less than 1 mm. Tables (markdown, for docs/simulation.md):

(a) load direction: the weight along each of +-x, +-y, +-z of the base (the
    gravity of the scenario turned, so the fingers' g(q) turns too), the torques
    re-solved for each; held, drift and rotation at two impedance gains;
(b) mass: the ball's mass raised until the simulation drops it, against the
    optimizer's load capacity (the first infeasible mass, by bisection);
(c) friction: the simulated friction (both coefficients) scaled below the planned
    one until the ball slips, at two impedance gains;
(d) the control: the impedance alone (no feedforward torque), at several gains;
(e) the impedance the bundled grasp needs, and the certified torques scaled by
    0.9 and 1.1 (the margin of the minimum-effort torques);
(f) friction margin (docs/planner.md): torques planned with margin k (the cone of
    mu/(1+k)) against the simulated friction lowered to 1/(1+k') of the planned
    one, for k, k' in 0, 0.1, 0.25, 0.5, at two gains;
(g) load capacity: the capacity LP's largest ball mass (alpha times the ball,
    with g(q0) as the node's offset) against the simulation: the ball's simulated
    mass set to a multiple of it, commanded the certified torques for that mass or,
    above the capacity, for 0.999 of it (the most the optimizer certifies).
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path
import subprocess
import sys
import time

import numpy as np

# The imports below need bench/ on sys.path for its sibling modules, so they follow
# code (E402) and stay out of the alphabetical block above (I100).
sys.path.insert(0, str(Path(__file__).resolve().parent))
from cycle import machine, report  # noqa: E402, I100
from grasp_torque_opt.core.resources import find_config  # noqa: E402
from grasp_torque_opt.core.scenario import load_scenario, Scenario, weight_wrench  # noqa: E402
from grasp_torque_opt.methods.capacity import load_capacity  # noqa: E402
from grasp_torque_opt.sim.hold import certified_torques, hold, HoldSettings  # noqa: E402
from grasp_torque_opt.sim.model import SimSettings  # noqa: E402

MARGINS = (0.0, 0.1, 0.25, 0.5)
CAPACITY_FACTORS = (0.9, 0.95, 0.999, 1.01, 1.02, 1.05, 1.1, 1.2)

DIRECTIONS = {'+x': (1, 0, 0), '-x': (-1, 0, 0), '+y': (0, 1, 0), '-y': (0, -1, 0),
              '+z': (0, 0, 1), '-z': (0, 0, -1)}


def loaded(scenario: Scenario, gravity=None, mass=None) -> Scenario:
    """Return the scenario with another gravity or ball mass, its load recomputed."""
    gravity = scenario.gravity if gravity is None else np.asarray(gravity, dtype=float)
    obj = scenario.object if mass is None else dataclasses.replace(scenario.object, mass=mass)
    wrench = scenario.extra_wrench + weight_wrench(obj, gravity, scenario.object_origin)
    return dataclasses.replace(scenario, gravity=gravity, object=obj, external_wrench=wrench)


def episode(scenario: Scenario, duration: float, kp: float, kd: float,
            feedforward: float = 1.0, friction: float = 1.0, mass: float | None = None) -> dict:
    """
    Run one hold episode, as a JSON-able record.

    ``mass``: the ball's simulated mass [kg] instead of the planned one.
    """
    sim = SimSettings(mu_tangential=friction * scenario.friction.mu1,
                      mu_torsional=friction * scenario.friction.mu2, mass=mass)
    r = hold(scenario, HoldSettings(kp=kp, kd=kd, duration=duration, feedforward=feedforward),
             sim)
    errors = [c.force_error for c in r.contacts if c.touching]
    return {'held': r.held, 'reason': r.reason, 'drift_mm': 1e3 * r.max_drift,
            'rotation_deg': float(np.degrees(r.rotation)), 'time_s': r.time,
            'max_force_error': max(errors) if errors and r.held else None,
            'max_effort_Nm': r.max_effort, 'wall_s': r.wall_time}


def cell(e: dict) -> str:
    """
    Format an episode's table cell.

    Held with its largest drift and final rotation; fell (left the grasp, > 20 mm) or
    slid (moved more than 1 mm, stayed in the hand), with when it passed 1 mm.
    """
    if e['held']:
        return f"held, {e['drift_mm']:.3f} mm, {e['rotation_deg']:.2f} deg"
    if e['drift_mm'] > 20.0:
        return f"**fell** (1 mm at {_passed(e['reason'])} s)"
    return f"**slid** {e['drift_mm']:.2f} mm (1 mm at {_passed(e['reason'])} s)"


def _passed(reason: str) -> str:
    marker = 'at t = '
    return reason.split(marker, 1)[1].split(' ', 1)[0] if marker in reason else '?'


def capacity(scenario: Scenario, low: float, high: float, tol: float = 1e-3) -> float:
    """Find the largest ball mass [kg] the optimizer certifies (bisection on the status)."""
    assert certified_torques(loaded(scenario, mass=low))[2].optimal
    while certified_torques(loaded(scenario, mass=high))[2].optimal:
        low, high = high, 2 * high
    while high - low > tol:
        mid = 0.5 * (low + high)
        low, high = (mid, high) if certified_torques(loaded(scenario, mass=mid))[2].optimal \
            else (low, mid)
    return low


def run(duration: float = 2.0, kd: float = 0.01, gains: tuple[float, float] = (0.3, 1.0)
        ) -> dict:
    base = load_scenario(find_config('allegro_right.yaml'))
    g = float(np.linalg.norm(base.gravity))
    out: dict = {'duration_s': duration, 'kd': kd, 'gains': list(gains)}

    rows = []
    for name, direction in DIRECTIONS.items():
        s = loaded(base, gravity=g * np.array(direction, dtype=float))
        _, _, sol, grav = certified_torques(s)
        row = {'direction': name, 'status': sol.status}
        if sol.optimal:
            row['max_command_Nm'] = float(np.abs(sol.tau + grav).max())
            row['episodes'] = {str(kp): episode(s, duration, kp, kd) for kp in gains}
        rows.append(row)
    out['directions'] = rows

    cap = capacity(base, base.object.mass, 2 * base.object.mass)
    masses = [m for m in (0.15, 0.3, 0.5, 0.7, 0.9) if m < cap] + [round(0.99 * cap, 3)]
    out['mass'] = {'capacity_kg': cap, 'rows': [
        {'mass': m, 'episodes': {str(kp): episode(loaded(base, mass=m), duration, kp, kd)
                                 for kp in gains + (3.0,)}} for m in masses]}

    factors = (1.0, 0.95, 0.9, 0.8, 0.7, 0.6, 0.5)
    out['friction'] = [{'factor': f, 'episodes': {str(kp): episode(base, duration, kp, kd,
                                                                   friction=f)
                                                  for kp in gains + (3.0,)}} for f in factors]

    out['control'] = [{'kp': kp, 'episode': episode(base, duration, kp, kd, feedforward=0.0)}
                      for kp in (0.3, 1.0, 3.0, 5.0)]

    out['margin'] = margin_rows(base, duration, kd, gains)
    out['capacity'] = capacity_rows(base, duration, kd)

    out['impedance'] = [{'kp': kp, 'episodes': {str(ff): episode(base, duration, kp, kd,
                                                                 feedforward=ff)
                                                for ff in (1.0, 0.9, 1.1)}}
                        for kp in (0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 1.0, 3.0)]
    return out


def with_margin(scenario: Scenario, k: float) -> Scenario:
    return dataclasses.replace(scenario, friction=dataclasses.replace(scenario.friction,
                                                                      margin=k))


def margin_rows(base: Scenario, duration: float, kd: float, gains) -> list[dict]:
    """(f): plan with margin k, simulate with the friction 1/(1+k') of the planned one."""
    rows = []
    for k in MARGINS:
        s = with_margin(base, k)
        _, _, sol, grav = certified_torques(s)
        rows.append({'margin': k, 'status': sol.status,
                     'usage_max': float(sol.friction_usage.max()),
                     'torque_norm': sol.torque_norm,
                     'max_command_Nm': float(np.abs(sol.tau + grav).max()),
                     'episodes': {f'{k2:g}': {str(kp): episode(s, duration, kp, kd,
                                                               friction=1 / (1 + k2))
                                              for kp in gains} for k2 in MARGINS}})
    return rows


def capacity_rows(base: Scenario, duration: float, kd: float, kp: float = 1.0) -> dict:
    """(g): the capacity LP's mass against the mass the simulated ball falls at."""
    setup, maps, _, _ = certified_torques(base)  # g(q0) as the offset, as the node
    cap = load_capacity(setup, maps)
    m_star = cap.value * base.object.mass
    rows = []
    for f in CAPACITY_FACTORS:
        m = f * m_star
        plan = loaded(base, mass=min(m, 0.999 * m_star))
        rows.append({'factor': f, 'mass': m, 'planned_mass': plan.object.mass,
                     'episode': episode(plan, duration, kp, kd, mass=m)})
    return {'alpha': cap.value, 'capacity_kg': m_star, 'kp': kp,
            'binding': cap.binding.text(), 'rows': rows}


def tables(r: dict) -> str:
    gains = [str(k) for k in r['gains']]
    lines = [f"(a) load direction (0.15 kg, weight along the base axis; Kd {r['kd']} N m s/rad, "
             f"{r['duration_s']:g} s)", '',
             '| weight along | max abs(tau + g) [N m] | '
             + ' | '.join(f'Kp {k} N m/rad' for k in gains) + ' |',
             '|---|---|' + '---|' * len(gains)]
    for row in r['directions']:
        if row['status'] != 'optimal':
            lines.append(f"| {row['direction']} | {row['status']} |" + ' - |' * len(gains))
            continue
        lines.append(f"| {row['direction']} | {row['max_command_Nm']:.3f} | "
                     + ' | '.join(cell(row['episodes'][k]) for k in gains) + ' |')
    mass_gains = gains + ['3.0']
    lines += ['', f'(b) mass (weight along +x); the optimizer certifies up to '
              f"{r['mass']['capacity_kg']:.3f} kg (first infeasible mass, bisection to 1 g)", '',
              '| mass [kg] | ' + ' | '.join(f'Kp {k}' for k in mass_gains) + ' |',
              '|---|' + '---|' * len(mass_gains)]
    for row in r['mass']['rows']:
        lines.append(f"| {row['mass']:g} | "
                     + ' | '.join(cell(row['episodes'][k]) for k in mass_gains) + ' |')
    lines += ['', '(c) simulated friction (mu_tangential and mu_torsional) as a share of the '
              'planned one', '',
              '| friction | ' + ' | '.join(f'Kp {k}' for k in mass_gains) + ' |',
              '|---|' + '---|' * len(mass_gains)]
    for row in r['friction']:
        lines.append(f"| {100 * row['factor']:.0f}% | "
                     + ' | '.join(cell(row['episodes'][k]) for k in mass_gains) + ' |')
    lines += ['', '(d) the control: impedance alone, no feedforward torque (g(q) still added)',
              '', '| Kp [N m/rad] | outcome |', '|---|---|']
    for row in r['control']:
        lines.append(f"| {row['kp']:g} | {cell(row['episode'])} |")
    lines += ['', '(e) the impedance the grasp needs; the certified torques scaled', '',
              '| Kp [N m/rad] | torques x 1.0 | x 0.9 | x 1.1 |', '|---|---|---|---|']
    for row in r['impedance']:
        e = row['episodes']
        lines.append(f"| {row['kp']:g} | {cell(e['1.0'])} | {cell(e['0.9'])} | "
                     f"{cell(e['1.1'])} |")
    lines += ['', '(f) friction margin: torques planned with margin k (the cone of mu/(1+k)) '
              "against simulated friction 1/(1+k') of the planned one "
              f"(Kp {' / '.join(gains)} N m/rad)", '',
              '| planned margin k | usage of the cone | norm tau [N m] | '
              + ' | '.join(f'friction {100 / (1 + float(k2)):.0f}%' for k2 in
                           r['margin'][0]['episodes']) + ' |',
              '|---|---|---|' + '---|' * len(r['margin'][0]['episodes'])]
    for row in r['margin']:
        lines.append(f"| {row['margin']:g} | {100 * row['usage_max']:.0f}% | "
                     f"{row['torque_norm']:.4f} | "
                     + ' | '.join(' / '.join(_short(e[k]) for k in gains)
                                  for e in row['episodes'].values()) + ' |')
    c = r['capacity']
    lines += ['', f"(g) load capacity: the capacity LP holds {c['alpha']:.3f} times the "
              f"0.15 kg ball, {c['capacity_kg']:.3f} kg ({c['binding']}); the simulated ball "
              f"at multiples of it, Kp {c['kp']:g} N m/rad, commanded the certified torques "
              'for its mass (above the capacity: for 0.999 of it)', '',
              '| mass / capacity | simulated mass [kg] | planned for [kg] | outcome |',
              '|---|---|---|---|']
    for row in c['rows']:
        lines.append(f"| {row['factor']:g} | {row['mass']:.3f} | {row['planned_mass']:.3f} | "
                     f"{cell(row['episode'])} |")
    for k in gains:
        errors = {row['direction']: row['episodes'][k]['max_force_error']
                  for row in r['directions'] if 'episodes' in row
                  and row['episodes'][k]['max_force_error'] is not None}
        if errors:
            lines += ['', f'Held episodes of (a) at Kp {k}: largest error of a simulated '
                      'contact force against its certified one, per direction: '
                      + ', '.join(f'{d} {100 * x:.1f}%' for d, x in errors.items()) + '.']
    return '\n'.join(lines)


def _short(e: dict) -> str:
    """Held / slid / fell in one word, for the margin grid."""
    return 'held' if e['held'] else ('**fell**' if e['drift_mm'] > 20.0 else '**slid**')


def _episodes(r: dict):
    for row in r['margin']:
        for per_gain in row['episodes'].values():
            yield from per_gain.values()
    for row in r['capacity']['rows']:
        yield row['episode']
    for row in r['directions']:
        yield from row.get('episodes', {}).values()
    for row in r['mass']['rows'] + r['friction'] + r['impedance']:
        yield from row['episodes'].values()
    for row in r['control']:
        yield row['episode']


def commit() -> str:
    try:
        return subprocess.run(['git', 'rev-parse', '--short', 'HEAD'], capture_output=True,
                              text=True, cwd=Path(__file__).parent, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return 'unknown'


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument('--duration', type=float, default=2.0, help='simulated hold [s]')
    p.add_argument('--kd', type=float, default=0.01, help='impedance damping [N m s/rad]')
    p.add_argument('--out', type=Path, default=Path('bench/results/physics.json'))
    a = p.parse_args()
    t0 = time.perf_counter()
    r = run(a.duration, a.kd)
    r['machine'], r['commit'] = machine(), commit()
    r['wall_s'] = time.perf_counter() - t0
    episodes = list(_episodes(r))
    simulated = sum(e['time_s'] + 0.2 for e in episodes)  # + the settling, 0.2 s each
    r['physics_speed'] = simulated / sum(e['wall_s'] for e in episodes)
    report(r, tables(r), a.out, f"commit {r['commit']}, {len(episodes)} episodes in "
           f"{r['wall_s']:.0f} s; the physics ran {r['physics_speed']:.0f}x faster than "
           "real time (MuJoCo steps and Pinocchio's g(q) each 1 ms step)")
    return 0


if __name__ == '__main__':
    sys.exit(main())
