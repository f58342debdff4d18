# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The CLI's JSON form of a solution (docs/design.md section 4), shared with the node's service."""

from __future__ import annotations

import json
import math
from typing import Any

from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.solution import Solution


def _finite_or_null(v: Any) -> Any:
    if isinstance(v, float):
        return v if math.isfinite(v) else None
    if isinstance(v, dict):
        return {k: _finite_or_null(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_finite_or_null(x) for x in v]
    return v


def strict_json(data: Any) -> str:
    """
    Return ``data`` as strict JSON (RFC 8259): a non-finite number becomes null.

    Python's ``json`` writes ``Infinity`` and ``NaN``, which strict parsers refuse;
    the certificate of a non-finite candidate has infinite residuals (docs/design.md
    section 4.2). Every JSON the package prints or answers goes through here.

    Written directly where every number is finite (``json`` then raises nothing): the
    same text, without first copying the data (a third of a full-metrics record's time).
    """
    try:
        return json.dumps(data, allow_nan=False)
    except ValueError:  # a non-finite number somewhere (json refuses it): null
        return json.dumps(_finite_or_null(data), allow_nan=False)


def _floats(a) -> list[float] | None:
    return None if a is None else [float(x) for x in a]


def solution_dict(solution: Solution, maps: GraspMaps) -> dict[str, Any]:
    """
    Plain data for JSON.

    Pinned keys: ``status``, ``method``, ``joints``, ``tau`` [N m],
    ``torque_norm`` [N m], ``solve_time_s``, ``certificate``, ``contacts`` (per
    contact ``link``, ``position``, ``normal``, ``tangent`` in the base frame and
    ``wrench`` [fx, fy, fz, mz] in the contact frame). Added: ``message``,
    ``iterations``, ``timings_s``, ``bounds`` (``tau-qp-adaptive``: ``lower``,
    ``upper`` [N m] on the exact-cone optimum of sqrt(tau^T W tau), ``gap``,
    ``tolerance``, ``converged``, ``rounds``, ``qp_solves``, ``source``; null for
    the other methods); ``objective``, ``friction_margin``, ``max_torque_ratio``,
    ``friction_usage_max``, per contact ``friction_usage`` (on the unreduced
    cone) and ``infeasibility`` (docs/planner.md). ``tau``, ``torque_norm``,
    every ``wrench``, the usages and the ratio are null unless the status is
    ``optimal``.
    """
    usage = solution.friction_usage
    contacts = []
    for i, frame in enumerate(maps.contacts):
        contacts.append({
            'link': frame.link,
            'position': _floats(frame.position),
            'normal': _floats(frame.normal),
            'tangent': _floats(frame.tangent),
            'wrench': None if solution.wrenches is None else _floats(solution.wrenches[i]),
            'friction_usage': None if usage is None else float(usage[i]),
        })
    return {
        'status': solution.status,
        'method': solution.method,
        'joints': list(solution.joints),
        'tau': _floats(solution.tau),
        'torque_norm': solution.torque_norm,
        'solve_time_s': solution.solve_time_s,
        'certificate': None if solution.certificate is None else solution.certificate.as_dict(),
        'contacts': contacts,
        'message': solution.message,
        'iterations': solution.iterations,
        'timings_s': dict(solution.timings),
        'bounds': None if solution.bounds is None else solution.bounds.as_dict(),
        'objective': solution.objective,
        'friction_margin': solution.friction_margin,
        'max_torque_ratio': solution.max_torque_ratio,
        'friction_usage_max': None if usage is None else float(max(usage)),
        'infeasibility': solution.infeasibility,
    }
