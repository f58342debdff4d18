# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Every method on one grasp, side by side (the paper's Table 2, extended)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.report import solution_dict
from grasp_torque_opt.core.solution import Solution
from grasp_torque_opt.methods.dispatch import METHODS, solve

LABELS = {
    'tau-qp': 'tau-QP (ours)',
    'tau-qp-adaptive': 'tau-QP adaptive',
    'force-qp': 'force QP',
    'socp': 'exact SOCP',
    'nlp': 'exact NLP',
}


@dataclass(frozen=True)
class Comparison:
    """
    Solutions of every method on one grasp.

    Attributes:
        maps: the grasp's kinematic maps.
        solutions: method -> solution, in :data:`METHODS` order.
    """

    maps: GraspMaps
    solutions: dict[str, Solution]

    def reduction(self, method: str) -> float | None:
        """Relative reduction of ||tau|| by the tau-QP against ``method`` [-]."""
        ours, other = self.solutions['tau-qp'].torque_norm, self.solutions[method].torque_norm
        return None if ours is None or not other else (other - ours) / other

    def excess_over_exact(self, method: str = 'tau-qp') -> float | None:
        """Relative excess of ``method``'s ||tau|| over the exact-cone optimum [-]."""
        ours, exact = self.solutions[method].torque_norm, self.solutions['socp'].torque_norm
        return None if ours is None or not exact else (ours - exact) / exact

    def as_dict(self) -> dict[str, Any]:
        """Plain data for JSON."""
        return {
            'methods': {m: solution_dict(s, self.maps) for m, s in self.solutions.items()},
            'reduction_vs': {m: self.reduction(m) for m in self.solutions if m != 'tau-qp'},
            'excess_over_exact': self.excess_over_exact(),
            'adaptive_excess_over_exact': self.excess_over_exact('tau-qp-adaptive'),
        }


def compare(setup: GraspSetup) -> Comparison:
    """Solve one grasp with every method."""
    maps = setup.maps()
    return Comparison(maps, {m: solve(setup, m, maps=maps) for m in METHODS})


def _pct(x: float | None) -> str:
    return '-' if x is None else f'{100.0 * x + 0.0:.1f}%'.replace('-0.0%', '0.0%')


def format_table(comparison: Comparison) -> str:
    """Format a fixed-width table: torques per joint and method, norms, reductions, times."""
    sols = comparison.solutions
    methods = list(sols)
    joints = next(iter(sols.values())).joints
    name_w = max(12, *(len(j) for j in joints))
    col_w = max(14, *(len(LABELS[m]) + 1 for m in methods))
    head = f"{'[N m]':<{name_w}}" + ''.join(f'{LABELS[m]:>{col_w}}' for m in methods)
    lines = [head, '-' * len(head)]

    def row(label: str, cells: list[str]) -> None:
        lines.append(f'{label:<{name_w}}' + ''.join(f'{c:>{col_w}}' for c in cells))

    for k, joint in enumerate(joints):
        row(joint, [f'{s.tau[k]:.4f}' if s.tau is not None else s.status for s in sols.values()])
    lines.append('-' * len(head))
    row('||tau||_2', [f'{s.torque_norm:.4f}' if s.tau is not None else s.status
                      for s in sols.values()])
    row('status', [s.status for s in sols.values()])
    row('tau-QP vs', ['-' if m == 'tau-qp' else _pct(comparison.reduction(m)) for m in methods])
    row('solve [ms]', [f'{1e3 * s.solve_time_s:.3f}' for s in sols.values()])
    row('iterations', [str(s.iterations) for s in sols.values()])
    bounded = [s.bounds for s in sols.values()]
    if any(b is not None for b in bounded):
        row('lower bound', ['-' if b is None or b.lower is None else f'{b.lower:.4f}'
                            for b in bounded])
        row('gap', ['-' if b is None or b.gap is None else f'{100 * b.gap:.3g}%'
                    for b in bounded])
    lines.append('')
    lines.append('tau-QP vs: reduction of ||tau||_2 by the tau-QP against each method '
                 '(negative: the tau-QP needs more).')
    lines.append(f'Excess of the tau-QP over the exact-cone optimum (SOCP): '
                 f'{_pct(comparison.excess_over_exact())}.')
    if 'tau-qp-adaptive' in sols:
        excess = comparison.excess_over_exact('tau-qp-adaptive')
        lines.append("Lower bound, gap: the adaptive method's certified bound on the "
                     "exact-cone optimum of sqrt(tau^T W tau) [N m] and its torque's gap to "
                     'it (docs/adaptive.md); its excess over the SOCP: '
                     + ('-' if excess is None else f'{100 * excess:.2g}%') + '.')
    return '\n'.join(lines)
