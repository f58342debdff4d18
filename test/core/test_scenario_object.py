# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The scenario's optional object and gravity: the load from the object's weight."""

import copy

from bad_scenarios import mutated
from conftest import ALLEGRO, CONFIG, PLANAR, scenario_doc
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.scenario import load_scenario, parse_scenario
import numpy as np
import pytest


@pytest.fixture(scope='module')
def weighed_doc():
    """Return the planar scenario with a box of 0.2 kg under gravity along -y, off-centre."""
    doc = scenario_doc(PLANAR)
    del doc['load']
    doc['gravity'] = [0.0, -9.81, 0.0]
    doc['object'] = {'shape': 'box', 'size': [0.07, 0.1, 0.02], 'mass': 0.2,
                     'position': [0.01, 0.11, 0.0], 'rpy': [0.0, 0.0, 0.3]}
    return doc


def test_bundled_allegro_load_is_the_balls_weight():
    s = load_scenario(ALLEGRO)
    assert s.object.shape == 'sphere' and s.object.size.tolist() == [0.04]
    np.testing.assert_array_equal(s.gravity, [9.81, 0.0, 0.0])
    np.testing.assert_allclose(s.object.position, s.object_origin)  # default: grasp origin
    # 0.15 kg * 9.81 m/s^2 along base +x, no moment about the ball's own centre.
    np.testing.assert_allclose(s.external_wrench, [1.4715, 0, 0, 0, 0, 0], atol=1e-12)


def test_weight_off_the_origin_has_a_moment(weighed_doc):
    s = parse_scenario(copy.deepcopy(weighed_doc), CONFIG)
    # F = 0.2 * (0, -9.81, 0) = (0, -1.962, 0) N at r = (0.01, 0, 0) m from the origin:
    # r x F = (0, 0, 0.01 * -1.962) N m.
    np.testing.assert_allclose(s.external_wrench, [0, -1.962, 0, 0, 0, -0.01962], atol=1e-12)
    np.testing.assert_array_equal(s.extra_wrench, np.zeros(6))
    np.testing.assert_array_equal(s.object.rpy, [0.0, 0.0, 0.3])


def test_an_external_wrench_adds_to_the_weight(weighed_doc):
    doc = copy.deepcopy(weighed_doc)
    doc['load'] = {'external_wrench': [1.0, 0.0, 0.0, 0.0, 0.5, 0.0]}
    s = parse_scenario(doc, CONFIG)
    np.testing.assert_allclose(s.external_wrench, [1, -1.962, 0, 0, 0.5, -0.01962], atol=1e-12)
    np.testing.assert_array_equal(s.extra_wrench, [1.0, 0.0, 0.0, 0.0, 0.5, 0.0])


def test_without_object_and_gravity_nothing_changes():
    s = load_scenario(PLANAR)
    assert s.object is None and s.gravity is None
    np.testing.assert_array_equal(s.external_wrench, scenario_doc(PLANAR)['load']
                                  ['external_wrench'])
    np.testing.assert_array_equal(s.extra_wrench, s.external_wrench)


def test_gravity_alone_leaves_the_load_as_written():
    doc = scenario_doc(PLANAR)
    doc['gravity'] = [0.0, 0.0, -9.81]
    s = parse_scenario(doc, CONFIG)
    np.testing.assert_array_equal(s.external_wrench, doc['load']['external_wrench'])


BAD = [
    (('object', 'shape'), 'cone', 'object.shape', 'must be one of sphere, box, cylinder'),
    (('object', 'shape'), None, 'object.shape', 'missing required field'),
    (('object', 'size'), [0.1, 0.1], 'object.size', 'must have 3 entries for a box'),
    (('object', 'size', 1), 0.0, r'object.size\[1\]', 'must be > 0'),
    (('object', 'mass'), -0.2, 'object.mass', 'must be > 0'),
    (('object', 'mass'), None, 'object.mass', 'missing required field'),
    (('object', 'position'), [0.0, 0.1], 'object.position', 'must have 3 entries'),
    (('object', 'rpy', 2), float('nan'), r'object.rpy\[2\]', 'must be finite'),
    (('object', 'colour'), 'red', 'object.colour', 'unknown field'),
    (('gravity',), [0.0, -9.81], 'gravity', 'must have 3 entries'),
    (('gravity',), 'down', 'gravity', 'must be a list of numbers'),
    (('gravity',), None, 'load', 'missing required field'),  # no weight: a load is needed
]


@pytest.mark.parametrize('path,value,field,problem', BAD)
def test_bad_object_or_gravity_names_its_field(weighed_doc, path, value, field, problem):
    with pytest.raises(InputError, match=rf'^{field}: .*{problem}'):
        parse_scenario(mutated(weighed_doc, path, value), CONFIG)
