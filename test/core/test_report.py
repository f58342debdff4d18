# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The package's JSON is strict: a non-finite number is written as null, never Infinity."""

import json

from grasp_torque_opt.core.certificate import certify
from grasp_torque_opt.core.report import solution_dict, strict_json
from grasp_torque_opt.methods.dispatch import solve
import numpy as np


def strict_loads(text: str):
    """Parse as a strict (RFC 8259) parser does: Infinity and NaN are errors."""
    def refuse(name):
        raise ValueError(f'not strict JSON: {name}')
    return json.loads(text, parse_constant=refuse)


def test_non_finite_numbers_become_null_at_any_depth():
    data = {'a': float('inf'), 'b': [1.0, float('nan'), (float('-inf'), 2.5)],
            'c': {'d': {'e': float('nan')}}, 'f': 'inf', 'g': 3, 'h': None}
    out = strict_loads(strict_json(data))
    assert out == {'a': None, 'b': [1.0, None, [None, 2.5]], 'c': {'d': {'e': None}},
                   'f': 'inf', 'g': 3, 'h': None}


def test_finite_numbers_round_trip_exactly():
    values = [0.1, 1e-300, -1.7976931348623157e308, 123456789.123456789, 5e-324]
    assert strict_loads(strict_json(values)) == values


def test_the_certificate_of_a_non_finite_candidate_is_strict_json(planar):
    maps = planar.maps()
    sol = solve(planar, maps=maps)
    tau = sol.tau.copy()
    tau[0] = np.nan
    cert = certify(maps.G, maps.J, planar.external_wrench, planar.friction,
                   -planar.hand.torque_limits, planar.hand.torque_limits, tau,
                   sol.wrenches.ravel())
    assert not cert.ok and cert.worst == float('inf')
    sol.certificate = cert
    out = strict_loads(strict_json(solution_dict(sol, maps)))
    assert out['certificate']['equilibrium'] is None
    assert out['certificate']['ok'] is False
    # Python's own json would have written Infinity here.
    assert 'Infinity' in json.dumps(solution_dict(sol, maps))


def test_finite_data_is_written_as_the_null_conversion_writes_it():
    # Written directly when every number is finite: the same text as through the
    # conversion (tuples as lists, NumPy floats, nesting, key order), byte for byte.
    from grasp_torque_opt.core.report import _finite_or_null
    data = {'z': (1.5, [np.float64(0.1), 2]), 'a': {'b': [1e-05, -0.0, 5e-324]},
            'k': 'x', 'n': None, 't': True}
    assert strict_json(data) == json.dumps(_finite_or_null(data), allow_nan=False)
    assert strict_json([np.float64('nan')]) == '[null]'
