# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Time the contacts from geometry per call, as the node would run them every cycle.

Usage: .venv/bin/python bench/geometry.py [--repeats 3000]

On the Allegro ball grasp (the fingers moving by 1 mrad jitter, as bench/cycle.py's):
the four tips against the ball by the closed form, the same by coal for every pair,
``contacts: auto`` (every link, coal for the boxes), and the tips against a mesh
object (a 12-triangle box, coal's BVH). Median and p99 [us]. Speed is measured here,
never asserted in a test.
"""

from __future__ import annotations

import argparse
from pathlib import Path
import tempfile
import time

from grasp_torque_opt.core.geometry_contacts import GeometryContacts
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import resolve_urdf
from grasp_torque_opt.core.object_geometry import object_pose, ObjectShape
from grasp_torque_opt.core.scenario import load_scenario
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
TIPS = ['link_3.0_tip', 'link_7.0_tip', 'link_11.0_tip', 'link_15.0_tip']


def box_mesh(path: Path, edges: list[float]) -> Path:
    """Write a box as a 12-triangle OBJ file."""
    h = 0.5 * np.asarray(edges)
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7),
             (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    lines = [f'v {sx * h[0]} {sy * h[1]} {sz * h[2]}' for sx in (-1, 1) for sy in (-1, 1)
             for sz in (-1, 1)]
    lines += ['f {} {} {}'.format(*(i + 1 for i in t)) for t in faces]
    path.write_text('\n'.join(lines) + '\n')
    return path


def time_calls(model: GeometryContacts, setup: GraspSetup, pose, repeats: int) -> dict:
    """Return the median and p99 of one ``contacts`` call [s], and the contacts found."""
    rng = np.random.default_rng(0)
    samples, found = [], 0
    for i in range(repeats + 50):
        q = setup.q.copy()
        q[setup.hand.idx_q] += rng.normal(scale=1e-3, size=setup.hand.m)
        t0 = time.perf_counter()
        contacts = model.contacts(q, pose)
        elapsed = time.perf_counter() - t0
        if i >= 50:
            samples.append(elapsed)
            found = contacts.p
    return {'median_s': float(np.median(samples)), 'p99_s': float(np.percentile(samples, 99)),
            'contacts': found}


def run(repeats: int = 3000) -> dict:
    """Time each case on the Allegro ball grasp."""
    scenario = load_scenario(ROOT / 'config' / 'allegro_right.yaml')
    setup = GraspSetup.from_scenario(scenario)
    urdf = resolve_urdf(scenario.urdf, scenario.base_dir)
    ball = object_pose(scenario.object.position)
    out = {}
    cases = {'tips, ball, closed form': {'links': TIPS},
             'tips, ball, coal': {'links': TIPS, 'analytic': False},
             'auto (20 links), ball': {}}
    for name, kwargs in cases.items():
        model = GeometryContacts.bind(setup.hand, urdf, scenario.object, **kwargs)
        out[name] = time_calls(model, setup, ball, repeats)
    with tempfile.TemporaryDirectory() as folder:
        mesh = ObjectShape.mesh_file(box_mesh(Path(folder) / 'box.obj', [0.03, 0.06, 0.045]))
        model = GeometryContacts.bind(setup.hand, urdf, mesh, links=TIPS, tolerance=0.05)
        out['tips, mesh box (12 triangles), coal'] = time_calls(
            model, setup, object_pose([0.062, 0.004, 0.03]), repeats)
    return out


def table(results: dict) -> str:
    """Format a markdown table of the cases [us]."""
    lines = ['| case | contacts | median [us] | p99 [us] |', '|---|---|---|---|']
    for name, r in results.items():
        lines.append(f"| {name} | {r['contacts']} | {1e6 * r['median_s']:.1f} | "
                     f"{1e6 * r['p99_s']:.1f} |")
    return '\n'.join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--repeats', type=int, default=3000)
    args = parser.parse_args()
    print(table(run(args.repeats)))


if __name__ == '__main__':
    main()
