# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
QP solvers side by side on the tau-QP, the exact-cone references, and warm starts.

Usage: .venv/bin/python bench/solvers.py [--grasps 200] [--seed 0] [--repeats 5]
       [--scenario-repeats 200] [--steps 500] [--warm-only] [--out bench/results/solvers.json]

The thread pools of BLAS/LAPACK are the environment's (recorded in the
output). OpenBLAS's default threads make the numpy/SciPy parts (SLSQP, the
problem building) many times slower on a busy 2-core machine; prefix the
command with OPENBLAS_NUM_THREADS=1 for times that do not depend on the
neighbours.

Problems: the two bundled scenarios and the seeded Allegro grasp set of
bench/grasps.py. Per grasp the tau-QP is built once (build_tau_qp); only the
solver call is timed (time.perf_counter around it; for the Clarabel, OSQP and
exact-cone rows that call includes the solver's own setup, since each grasp is a
new problem, and for ProxSuite it includes ``update``). Each solver is called
``--repeats`` times per grasp and the grasp's time is the **median** of those
calls (OSQP and SLSQP, much slower, are called once per grasp); the table
gives the median and p99 of that over the grasps (for a bundled scenario, one
grasp, over ``--scenario-repeats`` calls). Solvers take
turns grasp by grasp, so a burst of load on a shared machine hits all of them.

Rows:

- ``proxsuite``: make_solver("proxsuite"), the project's choice (the ratio
  column is against it).
- ``proxsuite-tuned``: the fastest ProxSuite dense variant (Hessian type,
  dense backend, eps_abs, preconditioner: computed on the first problem only
  as the project does, on every problem, or never) that has no failure and agrees with
  the reference to 1e-6 on a separate tuning set (seed + 1000, 50 grasps),
  preferring the tightest eps_abs among those within 10% of the fastest;
  chosen before, and reported on, the benchmark set.
- ``daqp``, ``quadprog``: make_solver.
- ``osqp``: the tau-QP, eps_abs = eps_rel = 1e-9, polishing on, 10000 iterations at most.
- ``clarabel-qp``: the tau-QP with Clarabel (tolerances 1e-10, as in conic.py).
- ``clarabel-socp``: the exact-cone SOCP (exact_socp.solve_exact_socp), a different problem.
- ``slsqp``: the exact cone with SciPy SLSQP (exact_nlp.solve_exact_nlp).

Every call's result is certified (certificate.certify on f = qp.wrenches(x)
for the tau-QP rows, f = x[:4p] for the exact rows); a grasp counts as failed
for a solver if any of its calls is not "solved" or fails the certificate.
Agreement is max |tau - tau_ref| over the grasps, tau_ref from an independent
formulation: the force-space QP with objective "torque" (Clarabel) for the
polygon rows, the SOCP for SLSQP; the SOCP row has no reference. For the exact
rows, "excess" is the torque-norm excess of the polygon optimum (the force-QP
reference) over that row's exact optimum, next to the time ratio.

Warm starts: 500 steps on the Allegro grasp of the scenario file, the load's
force rotating once around base y at constant magnitude (sequence "load"), the
same with every joint also drifting sinusoidally by up to 0.05 rad (sequence
"drift"), and the rotating load made 1000 times heavier (infeasible) for 10
steps in every 50 (sequence "step"). Per step the cold solve (make_solver) is
compared with the product's verified warm start (make_solver(...,
warm_start=True): ProxSuite's WARM_START_WITH_PREVIOUS_RESULT with the
preconditioner kept, DAQP's previous working set), including its cold redo of
a warm answer that is not solved or fails the certificate (both counted). A warm
result is bad if, after that, its verdict (certified or not) differs from the
cold one, or it lands more than 1e-6 (in tau, infinity norm) off the cold optimum.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
import dataclasses
from pathlib import Path
import sys
import time

import clarabel
import numpy as np
import osqp
import proxsuite
import scipy.sparse as sp

# The imports below need bench/ on sys.path for its sibling modules, so they follow
# code (E402) and stay out of the alphabetical block above (I100).
sys.path.insert(0, str(Path(__file__).resolve().parent))
from cycle import machine, report, ROOT, SCENARIOS  # noqa: E402, I100
from grasp_torque_opt.backends import make_solver  # noqa: E402
from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings  # noqa: E402
from grasp_torque_opt.control import compiled  # noqa: E402
from grasp_torque_opt.core.certificate import certify, DEFAULT_TOLERANCE  # noqa: E402
from grasp_torque_opt.core.grasp_setup import GraspSetup  # noqa: E402
from grasp_torque_opt.core.solution import RawResult  # noqa: E402
from grasp_torque_opt.core.tau_qp import build_tau_qp, TauQP  # noqa: E402
from grasp_torque_opt.reference.conic import solve_conic  # noqa: E402
from grasp_torque_opt.reference.exact_nlp import solve_exact_nlp  # noqa: E402
from grasp_torque_opt.reference.exact_socp import solve_exact_socp  # noqa: E402
from grasp_torque_opt.reference.force_qp import solve_force_qp  # noqa: E402
from grasps import allegro_grasps, blas_threads, SCENARIO  # noqa: E402

#: Two optima agree when their torques differ by at most this [N m].
AGREE_TOL = 1e-6
#: Size of the separate set the ProxSuite variant is tuned on, and its seed offset.
TUNING_GRASPS, TUNING_SEED_OFFSET = 50, 1000
OSQP_MAX_ITER = 10000
#: Rows too slow to call more than once per grasp.
SLOW_ROWS = ('osqp', 'slsqp')

DENSE = proxsuite.proxqp.dense
QP_ROWS = ['proxsuite', 'proxsuite-tuned', 'daqp', 'quadprog', 'osqp', 'clarabel-qp']
EXACT_ROWS = ['clarabel-socp', 'slsqp']


# ---------------------------------------------------------------- solvers


def variant_label(v: ProxSuiteSettings) -> str:
    return (f'HessianType.{v.hessian_type}, DenseBackend.{v.dense_backend}, eps_abs '
            f'{v.eps_abs:g}, preconditioner {v.preconditioner}')


def variant_grid() -> list[ProxSuiteSettings]:
    """List ProxSuite's dense variants: Hessian type, dense backend, tolerance, preconditioner."""
    return [ProxSuiteSettings(eps_abs=e, hessian_type=h, dense_backend=b, preconditioner=pc)
            for h in ('Dense', 'Diagonal')
            for b in ('Automatic', 'PrimalDualLDLT', 'PrimalLDLT')
            for e in (1e-9, 1e-8, 1e-7) for pc in ('first', 'every', 'off')]


def _finite_box(qp: TauQP) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows of the identity for the finite bounds: (rows for u_box, rows for l_box, eye)."""
    return np.isfinite(qp.u_box), np.isfinite(qp.l_box), np.eye(qp.H.shape[0])


def solve_osqp(qp: TauQP) -> RawResult:
    """OSQP on the tau-QP (setup and solve; a new problem per grasp)."""
    n = qp.H.shape[0]
    A = sp.csc_matrix(np.vstack((np.eye(n), qp.A, qp.C)))
    lo = np.concatenate((qp.l_box, qp.b, np.full(qp.C.shape[0], -np.inf)))
    hi = np.concatenate((qp.u_box, qp.b, qp.u))
    t0 = time.perf_counter()
    solver = osqp.OSQP()
    solver.setup(sp.triu(sp.csc_matrix(qp.H)).tocsc(), qp.g, A, lo, hi, eps_abs=1e-9,
                 eps_rel=1e-9, polishing=True, max_iter=OSQP_MAX_ITER, verbose=False)
    res = solver.solve()
    elapsed = time.perf_counter() - t0
    ok = res.info.status_val == osqp.SolverStatus.OSQP_SOLVED
    x = None if res.x is None else np.asarray(res.x, dtype=float)
    return RawResult('solved' if ok else 'error', x, int(res.info.iter), elapsed,
                     f'{res.info.status} (polish {res.info.status_polish})')


def solve_clarabel_qp(qp: TauQP) -> RawResult:
    """Clarabel on the tau-QP, through conic.solve_conic (its tolerances)."""
    hi, lo, eye = _finite_box(qp)
    A = np.vstack((qp.A, qp.C, eye[hi], -eye[lo]))
    b = np.concatenate((qp.b, qp.u, qp.u_box[hi], -qp.l_box[lo]))
    cones = ([clarabel.ZeroConeT(qp.A.shape[0])] if qp.A.shape[0] else []) + \
        [clarabel.NonnegativeConeT(len(b) - qp.A.shape[0])]
    return solve_conic(qp.H, qp.g, A, b, cones)


@dataclasses.dataclass
class Grasp:
    """One problem with everything the rows need."""

    setup: GraspSetup
    maps: object
    qp: TauQP
    tau_bounds: tuple[np.ndarray, np.ndarray]

    @classmethod
    def of(cls, setup: GraspSetup) -> Grasp:
        maps = setup.maps()
        tmin, tmax = setup.tau_bounds
        qp = build_tau_qp(maps, setup.friction, setup.external_wrench, tmin, tmax, setup.weights)
        return cls(setup, maps, qp, (tmin, tmax))

    @property
    def args(self) -> tuple:
        s = self.setup
        return (self.maps, s.friction, s.external_wrench, *self.tau_bounds, s.weights)

    def certify_tau_f(self, tau: np.ndarray, f: np.ndarray):
        s = self.setup
        return certify(self.maps.G, self.maps.J, s.external_wrench, s.friction,
                       *self.tau_bounds, tau, f)

    def from_qp(self, raw: RawResult):
        """(tau, f) of a tau-QP result, or (None, None)."""
        if raw.x is None:
            return None, None
        return self.qp.split(raw.x)[0], self.qp.wrenches(raw.x)

    def from_f(self, raw: RawResult):
        """(tau, f) of a result whose x starts with f."""
        if raw.x is None:
            return None, None
        f = raw.x[:self.maps.J.shape[0]]
        return self.maps.J.T @ f, f


def outcome(grasp: Grasp, raw: RawResult, kind: str) -> tuple[bool, np.ndarray | None, str]:
    """(certified, tau, why not) of one call."""
    tau, f = grasp.from_qp(raw) if kind == 'qp' else grasp.from_f(raw)
    if raw.status != 'solved' or tau is None:
        return False, tau, f'{raw.status}: {raw.message}'
    cert = grasp.certify_tau_f(tau, f)
    if not cert.ok:
        return False, tau, f'certificate failed (worst {cert.worst:.3g}; solver {raw.message})'
    return True, tau, ''


def make_rows(variant: ProxSuiteSettings) -> dict[str, tuple[str, Callable[[Grasp], RawResult]]]:
    """Row name -> (kind, call); each call sees only the grasp."""
    prox, tuned = make_solver('proxsuite'), make_solver('proxsuite', variant)
    daqp_, quadprog_ = make_solver('daqp'), make_solver('quadprog')
    return {
        'proxsuite': ('qp', lambda g: prox.solve(g.qp)),
        'proxsuite-tuned': ('qp', lambda g: tuned.solve(g.qp)),
        'daqp': ('qp', lambda g: daqp_.solve(g.qp)),
        'quadprog': ('qp', lambda g: quadprog_.solve(g.qp)),
        'osqp': ('qp', lambda g: solve_osqp(g.qp)),
        'clarabel-qp': ('qp', lambda g: solve_clarabel_qp(g.qp)),
        'clarabel-socp': ('exact', lambda g: solve_exact_socp(*g.args)),
        'slsqp': ('exact', lambda g: solve_exact_nlp(*g.args)),
    }


# ---------------------------------------------------------------- the comparison


def pct(a: list[float], q: float) -> float | None:
    return float(np.percentile(a, q)) if len(a) else None


def compare(setups: list[GraspSetup], repeats: int, variant: ProxSuiteSettings,
            rows: list[str] | None = None) -> dict:
    """Every row on every grasp: failures, agreement, times, ratios (see the module docstring)."""
    table_rows = make_rows(variant)
    names = rows or list(table_rows)
    per = {r: {'failed': 0, 'fail_examples': [], 'dev': [], 'times': [], 'samples': [],
               'iters': []} for r in names}
    ref_failed, excess = 0, {r: [] for r in EXACT_ROWS}
    single = len(setups) == 1
    for i, setup in enumerate(setups):
        g = Grasp.of(setup)
        ref_raw = solve_force_qp(*g.args, objective='torque')
        ok, tau_ref, why = outcome(g, ref_raw, 'exact')
        if not ok:
            ref_failed += 1
            tau_ref = None
        tau_exact = {}
        for r in names:
            kind, call = table_rows[r]
            times, good, tau, why = [], True, None, ''
            for _ in range(1 if r in SLOW_ROWS and not single else repeats):
                t0 = time.perf_counter()
                raw = call(g)
                times.append(time.perf_counter() - t0)
                ok, tau, why_k = outcome(g, raw, kind)
                if not ok and good:
                    good, why = False, why_k
            rec = per[r]
            rec['times'].append(float(np.median(times)))
            rec['samples'].extend(times)
            rec['iters'].append(raw.iterations)
            if not good:
                rec['failed'] += 1
                if len(rec['fail_examples']) < 5:
                    rec['fail_examples'].append({'grasp': i, 'why': why})
                continue
            if r in EXACT_ROWS:
                tau_exact[r] = tau
            ref = tau_ref if r in QP_ROWS else tau_exact.get('clarabel-socp') if r == 'slsqp' \
                else None
            if ref is not None:
                rec['dev'].append(float(np.max(np.abs(tau - ref))))
        for r, t in tau_exact.items():
            if tau_ref is not None:
                excess[r].append(float(np.linalg.norm(tau_ref) / np.linalg.norm(t) - 1.0))
    out = {'grasps': len(setups), 'repeats': repeats, 'reference_failed': ref_failed,
           'time_statistic': ('over the calls' if single else
                              'per grasp the median of the calls; then over the grasps'),
           'rows': {}}
    base = None
    for r in names:
        rec = per[r]
        t = rec['samples'] if single else rec['times']
        row = {'failed': rec['failed'], 'fail_examples': rec['fail_examples'],
               'agreement_n': len(rec['dev']),
               'max_abs_tau_dev': max(rec['dev']) if rec['dev'] else None,
               'median_s': pct(t, 50), 'p99_s': pct(t, 99),
               'iterations_median': float(np.median(rec['iters']))}
        if r == 'proxsuite':
            base = row['median_s']
        if r in EXACT_ROWS and excess[r]:
            e = excess[r]
            row['excess_polygon_over_exact'] = {'n': len(e), 'median': pct(e, 50),
                                                'p90': pct(e, 90), 'max': max(e)}
        out['rows'][r] = row
    for r, row in out['rows'].items():
        row['ratio_to_proxsuite'] = (row['median_s'] / base) if base else None
    return out


def tune_proxsuite(setups: list[GraspSetup], repeats: int) -> dict:
    """Every ProxSuite variant on the tuning set; the fastest without failure or disagreement."""
    grasps = [Grasp.of(s) for s in setups]
    refs = []
    for g in grasps:
        ok, tau, _ = outcome(g, solve_force_qp(*g.args, objective='torque'), 'exact')
        refs.append(tau if ok else None)
    tried = []
    for v in variant_grid():
        solver = make_solver('proxsuite', v)
        times, failed, dev = [], 0, 0.0
        for g, ref in zip(grasps, refs):
            ts, good = [], True
            for _ in range(repeats):
                t0 = time.perf_counter()
                raw = solver.solve(g.qp)
                ts.append(time.perf_counter() - t0)
                ok, tau, _ = outcome(g, raw, 'qp')
                good = good and ok
                if ok and ref is not None:
                    dev = max(dev, float(np.max(np.abs(tau - ref))))
            times.append(float(np.median(ts)))
            failed += not good
        tried.append({'variant': dataclasses.asdict(v), 'label': variant_label(v),
                      'failed': failed, 'max_abs_tau_dev': dev,
                      'median_s': float(np.median(times))})
    good = [t for t in tried if t['failed'] == 0 and t['max_abs_tau_dev'] <= AGREE_TOL]
    best = None
    if good:
        # Times are noisy: among the variants within 10% of the fastest, the
        # tightest eps_abs (the most margin under the certificate), then the fastest.
        fastest = min(t['median_s'] for t in good)
        near = [t for t in good if t['median_s'] <= 1.1 * fastest]
        best = min(near, key=lambda t: (t['variant']['eps_abs'], t['median_s']))
    return {'grasps': len(setups), 'tried': tried, 'best': best}


# ---------------------------------------------------------------- warm starts


def sequence(base: GraspSetup, steps: int, kind: str, seed: int = 0) -> list[GraspSetup]:
    """
    Return a slowly moving sequence: the load's force rotating once around base y.

    ``kind``: ``load`` only that; ``drift`` every joint also drifting sinusoidally by up
    to 0.05 rad; ``step`` the rotating load 1000 times heavier (infeasible) for 10
    steps out of every 50, then back.
    """
    scale = np.linalg.norm(base.external_wrench[:3])
    phase = np.random.default_rng(seed).uniform(0, 2 * np.pi, base.hand.m)
    out = []
    for k in range(steps):
        th = 2 * np.pi * k / steps
        w = np.array([scale * np.cos(th), 0.0, scale * np.sin(th), 0.0, 0.0, 0.0])
        if kind == 'step' and k % 50 >= 40:
            w *= 1e3
        q = base.q.copy()
        if kind == 'drift':
            q[base.hand.idx_q] += 0.05 * np.sin(th + phase)
        out.append(dataclasses.replace(base, q=q, external_wrench=w))
    return out


def warm_pair(grasps: list[Grasp], refs: list[np.ndarray | None], cold, warm) -> dict:
    """
    Cold and warm solvers on the same steps, in step order; refs: the force-QP taus.

    ``warm`` is the product's verified warm start (make_solver(..., warm_start=True)):
    a warm answer that is not solved is redone cold inside its call (counted by
    the solver, reported here as not solved), one that fails the certificate is
    redone cold here as :func:`grasp_torque_opt.methods.dispatch.solve` does, and
    its time counted in the warm column.
    """
    t_cold, t_warm, it_cold, it_warm = [], [], [], []
    cold_bad, not_solved, cert_failed, off, verdict = 0, 0, 0, 0, 0
    off_ref = {'cold': 0, 'warm': 0}
    worst = 0.0
    for g, ref in zip(grasps, refs):
        t0 = time.perf_counter()
        rc = cold.solve(g.qp)
        t_cold.append(time.perf_counter() - t0)
        redone = warm.fallbacks
        t0 = time.perf_counter()
        rw = warm.solve(g.qp)
        elapsed = time.perf_counter() - t0
        not_solved += warm.fallbacks > redone
        tau_w, f_w = g.from_qp(rw)
        if warm.last_warm and (tau_w is None or not g.certify_tau_f(tau_w, f_w).ok):
            cert_failed += 1
            t0 = time.perf_counter()
            rw = warm.solve(g.qp, cold=True)
            elapsed += time.perf_counter() - t0
            tau_w, f_w = g.from_qp(rw)
        t_warm.append(elapsed)
        it_cold.append(rc.iterations)
        it_warm.append(rw.iterations)
        ok_c, tau_c, _ = outcome(g, rc, 'qp')
        if not ok_c:
            cold_bad += 1
        elif ref is not None:
            off_ref['cold'] += float(np.max(np.abs(tau_c - ref))) > AGREE_TOL
        ok_w = rw.status == 'solved' and tau_w is not None and g.certify_tau_f(tau_w, f_w).ok
        verdict += ok_w != ok_c
        if not ok_w:
            continue
        if ref is not None:
            off_ref['warm'] += float(np.max(np.abs(tau_w - ref))) > AGREE_TOL
        if ok_c:
            d = float(np.max(np.abs(tau_w - tau_c)))
            worst = max(worst, d)
            off += d > AGREE_TOL
    return {'steps': len(grasps), 'cold_not_certified': cold_bad,
            'warm_not_solved': not_solved, 'warm_certificate_failed': cert_failed,
            'warm_off_cold_optimum': off, 'warm_verdict_differs': verdict,
            'warm_max_abs_tau_dev_from_cold': worst,
            'cold_off_reference': off_ref['cold'], 'warm_off_reference': off_ref['warm'],
            'cold_median_s': pct(t_cold, 50), 'cold_p99_s': pct(t_cold, 99),
            'warm_median_s': pct(t_warm, 50), 'warm_p99_s': pct(t_warm, 99),
            'cold_iterations_median': float(np.median(it_cold)),
            'warm_iterations_median': float(np.median(it_warm))}


def warm_compiled(grasps: list[Grasp], refs: list[np.ndarray | None]) -> dict:
    """
    Run the node's default, the compiled cycle (docs/design.md section 2.6), on the steps.

    Timed per step is its whole call (maps, build, warm solve, KKT check, certificate);
    a step it hands back (the node's Python cycle or fallback answers it) is counted,
    and its answers are held to the cold ProxSuite optimum and the force QP.
    """
    if not compiled.available():
        return {'skipped': compiled.IMPORT_ERROR}
    solver = make_solver('proxsuite', warm_start=True)
    cycle = compiled.CompiledCycle(grasps[0].setup, solver, DEFAULT_TOLERANCE)
    cold = make_solver('proxsuite')
    times, handed, off, worst = [], 0, 0, 0.0
    off_ref = {'cold': 0, 'warm': 0}
    cold_bad, verdict = 0, 0
    for g, ref in zip(grasps, refs):
        t0 = time.perf_counter()
        sol, _ = cycle.solve(g.setup, None)
        times.append(time.perf_counter() - t0)
        ok_c, tau_c, _ = outcome(g, cold.solve(g.qp), 'qp')
        cold_bad += not ok_c
        if ok_c and ref is not None:
            off_ref['cold'] += float(np.max(np.abs(tau_c - ref))) > AGREE_TOL
        verdict += (sol is not None) != ok_c
        if sol is None:
            handed += 1
            continue
        if ref is not None:
            off_ref['warm'] += float(np.max(np.abs(sol.tau - ref))) > AGREE_TOL
        if ok_c:
            d = float(np.max(np.abs(sol.tau - tau_c)))
            worst = max(worst, d)
            off += d > AGREE_TOL
    return {'steps': len(grasps), 'module': cycle.module.__name__.rsplit('.', 1)[-1],
            'handed_back': handed, 'warm_solves': solver.warm_solves,
            'warm_redone_cold': solver.fallbacks, 'verdict_differs': verdict,
            'cold_not_certified': cold_bad, 'off_cold_optimum': off,
            'max_abs_tau_dev_from_cold': worst, 'cold_off_reference': off_ref['cold'],
            'off_reference': off_ref['warm'], 'median_s': pct(times, 50),
            'p99_s': pct(times, 99)}


def warm_starts(steps: int, variant: ProxSuiteSettings) -> dict:
    base = GraspSetup.from_file(SCENARIO)
    out = {}
    for name in ('load', 'drift', 'step'):
        grasps = [Grasp.of(s) for s in sequence(base, steps, name)]
        refs = []
        for g in grasps:
            ok, tau, _ = outcome(g, solve_force_qp(*g.args, objective='torque'), 'exact')
            refs.append(tau if ok else None)
        out[name] = {
            'reference_not_certified': sum(r is None for r in refs),
            'proxsuite': warm_pair(grasps, refs, make_solver('proxsuite'),
                                   make_solver('proxsuite', warm_start=True)),
            'proxsuite-tuned': warm_pair(grasps, refs, make_solver('proxsuite', variant),
                                         make_solver('proxsuite', variant, warm_start=True)),
            'daqp': warm_pair(grasps, refs, make_solver('daqp'),
                              make_solver('daqp', warm_start=True)),
            'compiled': warm_compiled(grasps, refs),
        }
    return out


# ---------------------------------------------------------------- entry points


def run(grasps: int = 200, seed: int = 0, repeats: int = 5, scenario_repeats: int = 200,
        steps: int = 500, warm_only: bool = False) -> dict:
    """Run the whole benchmark (JSON-able): tuning, the three problem sets, warm starts."""
    if warm_only:  # the sequences alone, with the package's settings as the tuned row
        return {'machine': machine(), 'osqp': osqp.__version__, 'blas_threads': blas_threads(),
                'grasps': 0, 'seed': seed, 'repeats': repeats, 'tuning': None,
                'tuned_variant': 'not tuned (--warm-only)', 'sets': {},
                'warm_starts': warm_starts(steps, ProxSuiteSettings())}
    tuning = tune_proxsuite(allegro_grasps(TUNING_GRASPS, seed + TUNING_SEED_OFFSET),
                            max(1, min(repeats, 3)))
    variant = ProxSuiteSettings(**tuning['best']['variant']) if tuning['best'] else \
        ProxSuiteSettings()
    sets = {}
    for name in SCENARIOS:
        sets[name] = compare([GraspSetup.from_file(ROOT / 'config' / name)], scenario_repeats,
                             variant)
    sets[f'allegro grasp set ({grasps}, seed {seed})'] = compare(
        allegro_grasps(grasps, seed), repeats, variant)
    return {'machine': machine(), 'osqp': osqp.__version__, 'blas_threads': blas_threads(),
            'grasps': grasps, 'seed': seed, 'repeats': repeats,
            'tuning': tuning, 'tuned_variant': variant_label(variant), 'sets': sets,
            'warm_starts': warm_starts(steps, variant)}


def _us(x: float | None) -> str:
    return '-' if x is None else f'{1e6 * x:.0f}'


def table(results: dict) -> str:
    """Markdown tables: one per problem set, then the warm starts."""
    lines = [f"ProxSuite tuned: {results['tuned_variant']}", '']
    for name, res in results['sets'].items():
        lines += [f"**{name}** ({res['grasps']} grasp(s), {res['time_statistic']}; "
                  f"reference not certified: {res['reference_failed']})", '',
                  '| solver | failed | max abs tau - ref [N m] | median [us] | p99 [us] | '
                  'ratio to proxsuite | polygon excess over exact (median / max) |',
                  '|---|---:|---:|---:|---:|---:|---|']
        for r, row in res['rows'].items():
            dev = '-' if row['max_abs_tau_dev'] is None else f"{row['max_abs_tau_dev']:.1e}"
            ratio = ('-' if row['ratio_to_proxsuite'] is None
                     else f"{row['ratio_to_proxsuite']:.2f}")
            ex = row.get('excess_polygon_over_exact')
            ex = '' if not ex else f"{100 * ex['median']:.2f}% / {100 * ex['max']:.2f}%"
            lines.append(f"| {r} | {row['failed']} | {dev} | {_us(row['median_s'])} | "
                         f"{_us(row['p99_s'])} | {ratio} | {ex} |")
        rows = res['rows']
        slsqp = rows.get('slsqp', {})
        if slsqp.get('median_s') and slsqp.get('excess_polygon_over_exact'):
            ex = slsqp['excess_polygon_over_exact']
            speed = ', '.join(f"{r} {slsqp['median_s'] / rows[r]['median_s']:.0f}x"
                              for r in ('proxsuite', 'proxsuite-tuned', 'daqp', 'quadprog')
                              if rows.get(r, {}).get('median_s'))
            lines += ['', f'Faster than SLSQP on the exact cone (median over median; target '
                      f'1000x): {speed}; torque-norm excess of the polygon optimum over the '
                      f"exact one: median {100 * ex['median']:.2f}%, p90 {100 * ex['p90']:.2f}%,"
                      f" max {100 * ex['max']:.2f}%."]
        lines.append('')
    lines += ['**warm starts** (cold bad: not certified; warm redone cold: not solved / '
              'certificate failed; warm bad: verdict differs from the cold one / off the cold '
              'optimum by > 1e-6; off ref: > 1e-6 from the force QP)',
              '', '| sequence | solver | cold median / p99 [us] | warm median / p99 [us] | '
              'iterations cold / warm | cold bad | warm redone cold | warm bad | '
              'max abs warm - cold [N m] | off ref cold / warm |',
              '|---|---|---|---|---|---:|---|---|---:|---|']
    for seq, res in results['warm_starts'].items():
        for solver, w in res.items():
            if not isinstance(w, dict) or solver == 'compiled':
                continue
            lines.append(
                f"| {seq} ({w['steps']}) | {solver} | {_us(w['cold_median_s'])} / "
                f"{_us(w['cold_p99_s'])} | {_us(w['warm_median_s'])} / {_us(w['warm_p99_s'])} | "
                f"{w['cold_iterations_median']:.0f} / {w['warm_iterations_median']:.0f} | "
                f"{w['cold_not_certified']} | {w['warm_not_solved']} / "
                f"{w['warm_certificate_failed']} | {w['warm_verdict_differs']} / "
                f"{w['warm_off_cold_optimum']} | "
                f"{w['warm_max_abs_tau_dev_from_cold']:.1e} | {w['cold_off_reference']} / "
                f"{w['warm_off_reference']} |")
    lines += ['', "**the compiled cycle** (the node's default: maps, build, warm ProxSuite "
              'solve, KKT check and certificate in one call; handed back: left to the '
              'Python cycle and the fallback, as the infeasible steps must be)', '',
              '| sequence | module | median / p99 [us] | handed back | warm redone cold '
              '| verdict differs from cold | off the cold optimum / max abs [N m] '
              '| off ref |', '|---|---|---|---:|---|---:|---|---:|']
    for seq, res in results['warm_starts'].items():
        w = res.get('compiled')
        if not w:
            continue
        if 'skipped' in w:
            lines.append(f"| {seq} | skipped: {w['skipped']} | | | | | | |")
            continue
        lines.append(
            f"| {seq} ({w['steps']}) | {w['module']} | {_us(w['median_s'])} / "
            f"{_us(w['p99_s'])} | {w['handed_back']} | {w['warm_redone_cold']} of "
            f"{w['warm_solves']} | {w['verdict_differs']} | {w['off_cold_optimum']} / "
            f"{w['max_abs_tau_dev_from_cold']:.1e} | {w['off_reference']} |")
    return '\n'.join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--grasps', type=int, default=200)
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--repeats', type=int, default=5, help='calls per grasp (median taken)')
    parser.add_argument('--scenario-repeats', type=int, default=200)
    parser.add_argument('--steps', type=int, default=500, help='warm-start sequence length')
    parser.add_argument('--warm-only', action='store_true',
                        help='only the warm-start sequences (no tuning, no problem sets)')
    parser.add_argument('--out', type=Path, help='write the results as JSON here')
    args = parser.parse_args()
    res = run(args.grasps, args.seed, args.repeats, args.scenario_repeats, args.steps,
              args.warm_only)
    detail = ('warm-start sequences only' if args.warm_only else
              f'{args.grasps} grasps, seed {args.seed}, {args.repeats} calls per grasp')
    report(res, table(res), args.out, f"{detail}; threads: {res['blas_threads']}")


if __name__ == '__main__':
    main()
