# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Ranking scored candidates, and the words and table that report them."""

from __future__ import annotations

from collections.abc import Sequence
import math
from typing import Any

from grasp_torque_opt.core.report import strict_json

#: What a rank key sorts by: True for "larger is better".
RANK_KEYS = {'capacity': True, 'torque_norm': False, 'max_torque_ratio': False,
             'friction_usage_max': False}


def rank_key(records: Sequence[dict[str, Any]], by: str = 'capacity') -> str:
    """
    Return the key :func:`rank` sorts by.

    That is ``by``, or ``torque_norm`` for ``capacity`` when no record has one
    (``metrics="basic"``).

    Raises:
        ValueError: ``by`` is not one of :data:`RANK_KEYS`.
    """
    if by not in RANK_KEYS:
        raise ValueError(f"rank key must be one of {', '.join(RANK_KEYS)}, got {by!r}")
    if by == 'capacity' and not any('capacity' in r for r in records):
        return 'torque_norm'
    return by


#: The ranking's groups, in order: held (by the rank key), infeasible (by holdable
#: fraction), the rest (infeasible without a fraction, failed, bad lines).
GROUPS = ('feasible', 'infeasible', 'rest')


def rank_group(record: dict[str, Any]) -> str:
    """
    Return the group of :data:`GROUPS` a record is ranked in.

    ``feasible``: status ``optimal``; ``infeasible``: status ``infeasible`` with a
    holdable fraction (``metrics="full"``); ``rest``: everything else.
    """
    status = record.get('status')
    if status == 'optimal':
        return 'feasible'
    v = record.get('holdable_fraction')
    if status == 'infeasible' and v is not None and math.isfinite(v):
        return 'infeasible'
    return 'rest'


def rank(records: Sequence[dict[str, Any]], by: str = 'capacity') -> list[dict[str, Any]]:
    """
    Rank records: feasible ones by ``by``, then infeasible by holdable fraction, then the rest.

    Feasible (optimal) candidates come first, best first by ``by`` (:data:`RANK_KEYS`;
    without capacities, ``metrics="basic"``, ``capacity`` falls back to
    ``torque_norm``; one without a value after those with one); then infeasible
    candidates by their holdable fraction, largest first; then the rest
    (:func:`rank_group`), infeasible before failed before bad lines. Ties keep line
    order.
    """
    by = rank_key(records, by)
    larger = RANK_KEYS[by]

    def key(r: dict) -> tuple:
        group = GROUPS.index(rank_group(r))
        if group == 0:
            v = r.get(by)
            ok = v is not None and math.isfinite(v)
            return (0, not ok, (-v if larger else v) if ok else 0.0, r['line'])
        if group == 1:
            return (1, False, -r['holdable_fraction'], r['line'])
        order = {'infeasible': 0, 'failed': 1}.get(r.get('status'), 2)
        return (2, False, order, r['line'])

    return sorted(records, key=key)


def ranked_records(records: Sequence[dict[str, Any]], by: str = 'capacity'
                   ) -> list[dict[str, Any]]:
    """Set each record's ``rank`` (1 the best, :func:`rank`) in place; return them ranked."""
    ranked = rank(records, by)
    for i, r in enumerate(ranked, 1):
        r['rank'] = i
    return ranked


def summary(records: Sequence[dict[str, Any]], seconds: float) -> str:
    """One line: how many of each status, and the rate."""
    counts: dict[str, int] = {}
    for r in records:
        counts[r['status']] = counts.get(r['status'], 0) + 1
    parts = ', '.join(f'{counts.get(s, 0)} {s}' for s in ('optimal', 'infeasible', 'failed',
                                                          'error'))
    rate = len(records) / seconds if seconds > 0 else float('inf')
    return f'scored {len(records)} candidates in {seconds:.2f} s ({rate:.0f}/s): {parts}'


def format_table(ranked: Sequence[dict[str, Any]], top: int = 10) -> str:
    """Format the ranked table (text, not a contract)."""
    def num(v, fmt):
        return format(v, fmt) if v is not None else '-'.rjust(int(fmt.split('.')[0]))

    full = any('capacity' in r for r in ranked)
    head = f"{'rank':>4}  {'group':<10} {'line':>6}  {'id':<12} {'status':<10} " \
           f"{'|tau| N m':>9} {'max tau/lim':>11} {'friction':>8}"
    if full:
        head += f" {'capacity':>8} {'worst axis':>18}"
    lines = [head]
    for i, r in enumerate(ranked[:top], 1):
        row = (f"{i:>4}  {rank_group(r):<10} {r['line']:>6}  {str(r.get('id'))[:12]:<12} "
               f"{r['status']:<10} "
               f"{num(r.get('torque_norm'), '9.4f')} {num(r.get('max_torque_ratio'), '11.3f')} "
               f"{num(r.get('friction_usage_max'), '8.3f')}")
        if full:
            caps = {k: v for k, v in (r.get('capacities') or {}).items() if v is not None}
            worst = min(caps, key=caps.get) if caps else None
            unit = 'N m' if worst and worst[1] == 'M' else 'N'
            row += (f" {num(r.get('capacity'), '8.3f')} "
                    f"{(f'{worst} {caps[worst]:.3g} {unit}' if worst else '-'):>18}")
        lines.append(row)
    return '\n'.join(lines)


def record_json(record: dict[str, Any]) -> str:
    """Return one record as strict JSON (a non-finite number becomes null)."""
    return strict_json(record)
