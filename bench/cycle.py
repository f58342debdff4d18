# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Time the full control cycle on the bundled scenarios, per QP backend.

Usage: .venv/bin/python bench/cycle.py [--repeats 3000]
       [--backends proxsuite,daqp,quadprog,proxsuite+warm,daqp+warm]
       [--motions jitter,smooth] [--out FILE]

Two paths, median and p99 over the repeats, with the machine it ran on, for two
motions of the fingers (a warm start's work depends on how far the grasp moved):

- ``jitter``: every joint moves by a fresh random 1 mrad (standard deviation)
  between cycles, the hard case for a warm start;
- ``smooth``: every joint follows 2 mrad x sin(2 pi 1 Hz t + 0.4 j) sampled at
  1 kHz, as joint states from a hand holding a grasp arrive.

The paths:

- ``core``: kinematics and maps, build, solve, certificate (``solve.solve`` with
  a solver reused across cycles), with each stage's share of the total;
- ``controller``: what the node runs on each joint state, without ROS: the joint
  state checked and taken, then ``TorqueController.cycle`` (kinematics, gravity
  torques when compensated, maps, build, solve, certificate, gate), twice: as the
  node runs it by default (compiled where it applies, docs/design.md section 2.6;
  "compiled answered" counts its certified cycles) and with ``compiled=False``
  (the Python cycle everywhere).

With ``--params FILE`` it times only the cycle as the node makes it from a params file
(the bundled ``config/allegro_right_node.yaml``: its backend, its object loop and
margins), as the file says, with ``solver.backend`` ProxSuite and with the object loop
off, each with the joint states paced at 1 kHz of the wall clock (as the node meets
them: the caches cool between states) and back to back (the cycle's clock stepped 1 ms
a state: the cycle's own cost), the compiled call's stages from its own timings, and
the object loop's estimate from the fingertips per call, compiled and in numpy.

With ``--geometry`` it also times the contacts from geometry per call
(``bench/geometry.py``: the Allegro's tips against the ball by the closed form and by
coal, ``contacts: auto``, a mesh object), what the node would add to each cycle.

Speed is measured here, never asserted in a test.
"""

from __future__ import annotations

import argparse
import dataclasses
from datetime import datetime, timezone
from importlib import metadata
import json
import os
from pathlib import Path
import platform
import time

from grasp_torque_opt.backends import BACKENDS, make_solver, single_threaded_math
from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.control.geometry import ContactTracker
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.parameters.generated import CycleConfig
from grasp_torque_opt.core.geometry_contacts import GeometryContacts
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import resolve_urdf
from grasp_torque_opt.core.object_geometry import object_pose
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.methods.dispatch import solve
import numpy as np
import yaml

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ['planar_two_finger.yaml', 'allegro_right.yaml']
STAGES = ['maps', 'build', 'solve', 'certify']


def machine() -> dict:
    """Describe the machine this ran on: CPU, cores, Python, versions, date."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path('/proc/cpuinfo').read_text().splitlines():
            if line.startswith('model name'):
                cpu = line.split(':', 1)[1].strip()
                break
    except OSError:
        pass
    versions = {}
    for p in ('numpy', 'pin', 'proxsuite', 'daqp', 'quadprog', 'scipy', 'clarabel'):
        try:
            versions[p] = metadata.version(p)
        except metadata.PackageNotFoundError:
            versions[p] = None
    return {'cpu': cpu, 'cores': os.cpu_count(), 'python': platform.python_version(),
            'system': platform.platform(), 'versions': versions,
            'date': datetime.now(timezone.utc).strftime('%Y-%m-%d %H:%M UTC')}


def machine_line(m: dict) -> str:
    """Return one line naming the machine and the date."""
    return (f"machine: {m['cpu']}, {m['cores']} cores, Python {m['python']}, "
            f"ProxSuite {m['versions']['proxsuite']}, DAQP {m['versions']['daqp']}, "
            f"Pinocchio {m['versions']['pin']}; {m['date']}")


def report(results: dict, table_text: str, out: Path | None, detail: str = '') -> None:
    """Print the machine line (with ``detail``) and the table; write the JSON to ``out``."""
    print(machine_line(results['machine']) + (f'; {detail}' if detail else ''))
    print(table_text)
    if out:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(results, indent=2))


def summary(samples: list[float]) -> dict:
    """Return the median and p99 [s]."""
    return {'median_s': float(np.median(samples)), 'p99_s': float(np.percentile(samples, 99))}


def solver_of(variant: str):
    """Make a solver from a variant name: a backend, ``+warm`` for its verified warm start."""
    backend, _, warm = variant.partition('+')
    return make_solver(backend, warm_start=warm == 'warm')


#: Motions of the fingers from cycle to cycle (see the module's docstring).
MOTIONS = ('jitter', 'smooth')


def offsets(m: int, count: int, motion: str) -> np.ndarray:
    """Return joint offsets from the grasp's q, shape (count, m) [rad]."""
    if motion == 'jitter':
        return np.random.default_rng(0).normal(scale=1e-3, size=(count, m))
    t = np.arange(count)[:, None] * 1e-3  # 1 kHz
    return 2e-3 * np.sin(2.0 * np.pi * t + 0.4 * np.arange(m))


def moving(setup: GraspSetup, count: int, motion: str = 'jitter') -> list[GraspSetup]:
    """Return the grasp with the fingers moving by ``motion`` from cycle to cycle."""
    out = []
    for dq in offsets(setup.hand.m, count, motion):
        q = setup.q.copy()
        q[setup.hand.idx_q] += dq
        out.append(dataclasses.replace(setup, q=q))
    return out


def bench_core(setup: GraspSetup, variant: str, repeats: int, motion: str = 'jitter'
               ) -> dict:
    """
    Time the core cycle on a moving grasp: maps, build, solve, certify; per stage, total.

    As in the node, DAQP is the fallback of the other backends; ``fallbacks``
    counts the cycles it answered, ``failed`` those nobody certified.
    """
    solver = solver_of(variant)
    fallback = None if variant.startswith('daqp') else make_solver('daqp')
    sol = solve(setup, solver=solver)
    if not sol.optimal:
        return {'skipped': sol.message}
    samples = {k: [] for k in STAGES + ['total']}
    fallbacks = failed = 0
    for i, grasp in enumerate(moving(setup, repeats + 50, motion)):
        t0 = time.perf_counter()
        sol = solve(grasp, solver=solver, fallback=fallback)
        total = time.perf_counter() - t0
        if i < 50:  # warm-up
            continue
        fallbacks += sol.optimal and sol.backend != solver.name
        if not sol.optimal:
            failed += 1
            continue
        samples['total'].append(total)
        for k in STAGES:
            samples[k].append(sol.timings[k])
    out = {k: summary(v) for k, v in samples.items()}
    total = sum(out[k]['median_s'] for k in STAGES)
    for k in STAGES:
        out[k]['share'] = out[k]['median_s'] / total
    out['fallbacks'], out['failed'] = int(fallbacks), failed
    return out


def timed_cycles(ctrl: TorqueController, setup: GraspSetup, repeats: int, motion: str,
                 paced: bool = False, step: float | None = None):
    """
    Yield (seconds, result) of ``repeats`` cycles after 50 of warm-up: take a state, cycle.

    ``paced``: one joint state a millisecond of the monotonic clock (as at 1 kHz), else
    back to back. ``step``: the cycle's clock (receipt times) advances by ``step`` seconds
    per joint state from the first, whatever the wall clock does (back to back, the node's
    inputs still arrive at 1 kHz for ``step`` 1e-3); None: the monotonic clock.
    """
    names = list(setup.hand.joints)
    q0 = setup.q[setup.hand.idx_q]
    start = time.monotonic()
    for i, dq in enumerate(offsets(q0.size, repeats + 50, motion)):
        positions = (q0 + dq).tolist()
        now = time.monotonic() if step is None else start + i * step
        t0 = time.perf_counter()
        ctrl.take('joint_states', JointStateReading(names, positions), now)
        result = ctrl.cycle(now)
        elapsed = time.perf_counter() - t0
        if i >= 50:
            yield elapsed, result
        while paced and time.monotonic() < now + 1e-3:
            pass


def bench_controller(setup: GraspSetup, variant: str, repeats: int, motion: str = 'jitter',
                     compiled: bool = True, scenario=None) -> dict:
    """
    Time the node's cycle without ROS: take a joint state, then run the cycle.

    ``scenario``: its contacts found from geometry every cycle (the node's
    contact_geometry.enabled, its scenario's contact links, 1 mm).
    """
    backend = variant.partition('+')[0]
    ctrl = TorqueController(setup, CycleConfig(gravity_compensation=True, compiled=compiled),
                            backend=backend,
                            warm_start=variant.endswith('+warm'),
                            fallback=None if backend == 'daqp' else 'daqp')
    if scenario is not None:  # as the node's configure binds it (grasp_source.place_object)
        obj = scenario.object
        ctrl.solving.object = obj
        ctrl.solving.scenario_pose = object_pose(obj.position, obj.rpy)
        ctrl.solving.tracker = ContactTracker(GeometryContacts.bind(
            setup.hand, resolve_urdf(scenario.urdf, scenario.base_dir), obj, 1e-3,
            [c.link for c in scenario.contacts]), obj)
    samples, published = [], 0
    for elapsed, result in timed_cycles(ctrl, setup, repeats, motion):
        samples.append(elapsed)
        published += result.kind == 'solution'
    solver = ctrl.solver
    fast = ctrl.compiled_cycle
    return {'total': summary(samples), 'certified_commands': published, 'cycles': repeats,
            'warm_solves': getattr(solver, 'warm_solves', 0),
            'warm_start_fallbacks': getattr(solver, 'fallbacks', 0),
            'compiled_solves': fast.solves if fast is not None else 0,
            'compiled_handed_back': fast.handed_back if fast is not None else 0,
            'python_because': ctrl.compiled_reason if fast is None or fast.gave_up else ''}


#: What is timed: each backend, and DAQP with its verified warm start.
VARIANTS = (*BACKENDS, 'proxsuite+warm', 'daqp+warm')


def run(repeats: int = 3000, backends: tuple[str, ...] = VARIANTS,
        motions: tuple[str, ...] = MOTIONS) -> dict:
    """Time every scenario, motion and backend, both paths."""
    out = {'machine': machine(), 'repeats': repeats, 'scenarios': {}}
    for name in SCENARIOS:
        setup = GraspSetup.from_file(ROOT / 'config' / name)
        res = out['scenarios'][name] = {}
        for motion in motions:
            for b in backends:
                core = bench_core(setup, b, repeats, motion)
                r = res[f'{b} {motion}'] = {'core': core}
                if 'skipped' not in core:
                    r['controller'] = bench_controller(setup, b, repeats, motion)
                    r['controller_python'] = bench_controller(setup, b, repeats, motion,
                                                              compiled=False)
    return out


def node_geometry(repeats: int) -> dict:
    """Time the Allegro's node cycle (ProxSuite, warm) with contacts from geometry off and on."""
    path = ROOT / 'config' / 'allegro_right.yaml'
    setup, scenario = GraspSetup.from_file(path), load_scenario(path)
    out = {}
    for compiled in (True, False):
        for on in (False, True):
            r = bench_controller(setup, 'proxsuite+warm', repeats, 'jitter', compiled,
                                 scenario if on else None)
            kind = 'compiled' if compiled else 'Python'
            out[f"{kind} cycle, geometry {'on' if on else 'off'}"] = r
    return out


def node_geometry_table(results: dict) -> str:
    """Format the node cycle with geometry off and on: medians, p99 [us], certified."""
    lines = ['| node cycle | median | p99 | certified |', '|---|---|---|---|']
    for name, r in results.items():
        t = r['total']
        lines.append(f"| {name} | {1e6 * t['median_s']:.1f} | {1e6 * t['p99_s']:.1f} | "
                     f"{r['certified_commands']} of {r['cycles']} |")
    return '\n'.join(lines) + '\n\n(times in us)'


#: The params-file cycle's variants: name -> parameters over the file's, each
#: ``section.field`` (none: as is).
PARAMS_VARIANTS = {'as the file says': {},
                   'backend proxsuite, fallback daqp': {'solver.backend': 'proxsuite',
                                                        'solver.fallback': 'daqp'},
                   'object loop off': {'object_loop.enabled': False}}

#: How the joint states come (bench_params): paced at 1 kHz of the wall clock, as the
#: node meets them (its caches cooled between states), and back to back with the cycle's
#: clock stepped 1 ms a state (the same inputs, the caches warm: the cycle's own cost).
PACINGS = {'paced': {'paced': True}, 'back to back': {'step': 1e-3}}


def overridden(p, over: dict):
    """Return params ``p`` with ``over``'s ``section.field`` values replaced."""
    for key, value in over.items():
        section, _, name = key.partition('.')
        p = dataclasses.replace(p, **{section: dataclasses.replace(getattr(p, section),
                                                                   **{name: value})})
    return p


def bench_params(params: Path, repeats: int, motion: str) -> dict:
    """
    Time the cycle as the node makes it from a params file, per :data:`PARAMS_VARIANTS`.

    The controller is the node's own (``sim_compare.params_file`` and the node's
    ``configure``), the object's estimate from the fingertips placed as the node places
    it, with the scenario's load, object and weight bound as the node binds them
    (``grasp_source.bind_scenario``: the object loop and the effort estimation run as
    in the node); joint states only (no IMU, contacts or wrench messages, as
    ``bench/node_blackbox.py`` sends them), a new controller per variant and pacing
    (:data:`PACINGS`). Per variant and pacing: the cycle (take and cycle) median and
    p99, and the compiled call's stages (its own timings) with the solver's iterations,
    medians.
    """
    from grasp_torque_opt.ros.node.controllers import configure
    from grasp_torque_opt.ros.node.grasp_source import bind_scenario
    from grasp_torque_opt.ros.sim_compare import params_file

    doc = yaml.safe_load(params.read_text())
    name = next(iter(doc.values()))['ros__parameters']['scenario']
    path = ROOT / 'config' / name
    scenario, setup = load_scenario(path), GraspSetup.from_file(path)
    out = {'params': str(params.relative_to(ROOT)) if params.is_relative_to(ROOT) else
           str(params), 'motion': motion, 'variants': {}}
    for variant, over in PARAMS_VARIANTS.items():
        out['variants'][variant] = {}
        for pacing, how in PACINGS.items():
            p = overridden(params_file(params, scenario, setup), over)
            ctrl = configure(None, setup, p, obj=scenario.object)
            bind_scenario((ctrl,), scenario, p, '')
            samples, stages, published = [], {k: [] for k in (*STAGES, 'iterations')}, 0
            for elapsed, result in timed_cycles(ctrl, setup, repeats, motion, **how):
                samples.append(elapsed)
                published += result.kind == 'solution'
                sol = result.solution
                if sol is not None and sol.timings:
                    for k in STAGES:
                        stages[k].append(sol.timings[k])
                    stages['iterations'].append(sol.iterations)
            fast = ctrl.compiled_cycle
            out['variants'][variant][pacing] = {
                'backend': ctrl.solver.name, 'total': summary(samples), 'certified': published,
                'cycles': repeats, 'compiled_solves': fast.solves if fast is not None else 0,
                'stages_median': {k: float(np.median(v)) if v else None
                                  for k, v in stages.items()}}
            if not over and pacing == 'paced':
                out['estimate'] = estimate_times(ctrl, setup, repeats, motion)
    return out


def estimate_times(ctrl: TorqueController, setup: GraspSetup, repeats: int, motion: str
                   ) -> dict | None:
    """
    Time the object loop's estimate from the fingertips per call, compiled and in numpy.

    The loop's own tracker (the compiled points and fit, as the node runs it) and its
    numpy twin on the same reference, alternating call by call on the run's joint
    states; medians and p99 [s]. None when the loop has no tracker.
    """
    from grasp_torque_opt.core.object_from_hand import ObjectFromHand

    tracker = ctrl.solving.object_loop.tracker
    if tracker is None:
        return None
    # (joint states only: the loop's contacts are the scenario's)
    twin = ObjectFromHand(setup.hand, setup.contacts, tracker.q0, tracker.pose0)
    q = setup.q.copy()
    times = {'compiled': [], 'numpy': []}
    for dq in offsets(setup.hand.m, repeats, motion):
        q[setup.hand.idx_q] = setup.q[setup.hand.idx_q] + dq
        for name, est in (('compiled', tracker), ('numpy', twin)):
            t0 = time.perf_counter()
            est.estimate(q)
            times[name].append(time.perf_counter() - t0)
    return {'module': tracker.compiled is not None,
            **{k: summary(v) for k, v in times.items()}}


def params_table(r: dict) -> str:
    """Format the params-file cycle's table [us]."""
    lines = [f"the cycle as the node makes it from {r['params']} ({r['motion']} motion, joint "
             'states only; paced: one a millisecond of the wall clock; back to back: the '
             "cycle's clock stepped 1 ms a state):", '',
             '| variant | joint states | backend | cycle median | cycle p99 | certified '
             '| compiled answered | compiled maps | build | solve | certify '
             '| solver iterations (median) |',
             '|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|']
    for name, paced in r['variants'].items():
        for pacing, v in paced.items():
            st = v['stages_median']
            us = ' | '.join('-' if st[k] is None else f'{1e6 * st[k]:.1f}' for k in STAGES)
            lines.append(f"| {name} | {pacing} | {v['backend']} | "
                         f"{1e6 * v['total']['median_s']:.0f} | "
                         f"{1e6 * v['total']['p99_s']:.0f} | {v['certified']} of {v['cycles']} "
                         f"| {v['compiled_solves']} | {us} | {st['iterations'] or '-'} |")
    e = r.get('estimate')
    if e is not None:
        lines += ['', "the object loop's estimate from the fingertips, per call (the same "
                  'joint states, alternating): compiled '
                  f"{1e6 * e['compiled']['median_s']:.1f} us median, "
                  f"{1e6 * e['compiled']['p99_s']:.1f} p99"
                  + ('' if e['module'] else ' (the module did not take the hand: numpy)')
                  + f"; numpy {1e6 * e['numpy']['median_s']:.1f} us median, "
                  f"{1e6 * e['numpy']['p99_s']:.1f} p99"]
    return '\n'.join(lines)


def table(results: dict) -> str:
    """Format a markdown table: per scenario and backend, stage medians [us], totals."""
    head = ('| scenario | backend, motion | maps | build | solve | certify | core median '
            '| core p99 | fallbacks / failed | node cycle median | node cycle p99 '
            '| warm redone cold | compiled answered | Python cycle median | Python cycle p99 |')
    lines = [head, '|' + '---|' * 15]
    for name, res in results['scenarios'].items():
        for b, r in res.items():
            core = r['core']
            if 'skipped' in core:
                lines.append(f"| {name} | {b} | - | - | - | - | skipped: {core['skipped']} "
                             '| | | | | | | | |')
                continue
            stages = ' | '.join(f"{1e6 * core[k]['median_s']:.0f} ({100 * core[k]['share']:.0f}%)"
                                for k in STAGES)
            c = r['controller']
            ctl, py = c['total'], r['controller_python']['total']
            redone = (f"{c['warm_start_fallbacks']} of {c['warm_solves']}" if '+warm' in b
                      else '-')
            answered = (f"{c['compiled_solves']} of {c['cycles'] + 50}" if c['compiled_solves']
                        else f"0 ({c['python_because'].split(' (')[0]})")
            lines.append(f"| {name} | {b} | {stages} | {1e6 * core['total']['median_s']:.0f} | "
                         f"{1e6 * core['total']['p99_s']:.0f} | {core['fallbacks']} / "
                         f"{core['failed']} | {1e6 * ctl['median_s']:.0f} | "
                         f"{1e6 * ctl['p99_s']:.0f} | {redone} | {answered} | "
                         f"{1e6 * py['median_s']:.0f} | {1e6 * py['p99_s']:.0f} |")
    return '\n'.join(lines) + ('\n\n(times in us; share of the core cycle in parentheses; '
                               "the core cycle is the library's Python solve)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--repeats', type=int, default=3000)
    parser.add_argument('--backends', default=','.join(VARIANTS))
    parser.add_argument('--motions', default=','.join(MOTIONS))
    parser.add_argument('--out', type=Path, help='also write the results here (JSON)')
    parser.add_argument('--geometry', action='store_true',
                        help='also time the contacts from geometry (bench/geometry.py)')
    parser.add_argument('--params', type=Path, metavar='FILE',
                        help='only the cycle as the node makes it from this params file '
                        '(e.g. config/allegro_right_node.yaml), as the file says and with '
                        'ProxSuite; the first of --motions')
    args = parser.parse_args()
    single_threaded_math()
    if args.params is not None:
        results = {'machine': machine(), 'repeats': args.repeats,
                   'params': bench_params(args.params.resolve(), args.repeats,
                                          args.motions.split(',')[0])}
        report(results, params_table(results['params']), args.out)
        return
    results = run(args.repeats, tuple(args.backends.split(',')),
                  tuple(args.motions.split(',')))
    text = table(results)
    if args.geometry:
        import geometry  # bench/geometry.py, beside this file

        results['geometry'] = geometry.run(args.repeats)
        text += '\n\ncontacts from geometry, per call:\n' + geometry.table(results['geometry'])
        results['node_geometry'] = node_geometry(args.repeats)
        text += '\n\nthe node cycle, contacts from geometry off and on:\n' + \
            node_geometry_table(results['node_geometry'])
    report(results, text, args.out)


if __name__ == '__main__':
    main()
