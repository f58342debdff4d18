# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Scenario documents made bad one field at a time, with the field each error must name."""

import copy
import math


def mutated(doc, path, value):
    """Copy ``doc`` with the item at ``path`` (keys and indices) set, or removed if None."""
    out = copy.deepcopy(doc)
    node = out
    for key in path[:-1]:
        node = node[key]
    if value is None:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return out


BAD = [
    # (path, value, field named, problem)
    (('hand', 'urdf'), None, 'hand.urdf', 'missing required field'),
    (('load',), None, 'load', 'missing required field'),
    (('grasp', 'object_origin'), None, 'grasp.object_origin', 'missing required field'),
    (('friction', 'mu_torsional'), None, 'friction.mu_torsional', 'missing required field'),
    (('grasp', 'contacts', 0, 'link'), None, r'grasp.contacts\[0\].link', 'missing'),
    (('hand', 'joints', 1), 'joint9', r'hand.joints\[1\]', "unknown joint 'joint9'"),
    (('hand', 'joints', 1), 'joint1', r'hand.joints\[1\]', "duplicate name 'joint1'"),
    (('grasp', 'joint_positions', 'jointX'), 0.1, 'grasp.joint_positions.jointX',
     "unknown joint 'jointX'"),
    (('grasp', 'contacts', 1, 'link'), 'finger3_tip', r'grasp.contacts\[1\].link',
     "unknown frame 'finger3_tip'"),
    (('load', 'external_wrench', 2), math.nan, r'load.external_wrench\[2\]', 'must be finite'),
    (('grasp', 'object_origin', 0), math.inf, r'grasp.object_origin\[0\]', 'must be finite'),
    (('load', 'external_wrench'), [0, 1, 2], 'load.external_wrench', 'must have 6 entries'),
    (('hand', 'torque_limits'), [1, 2, 3], 'hand.torque_limits', 'must have 4 entries'),
    (('hand', 'torque_limits'), -1.0, 'hand.torque_limits', 'must be > 0'),
    (('grasp', 'contacts', 0, 'position'), [0, 0], r'grasp.contacts\[0\].position',
     'must have 3 entries'),
    (('friction', 'polygon_sides'), 2, 'friction.polygon_sides', 'must be >= 3'),
    (('friction', 'polygon_sides'), 3.5, 'friction.polygon_sides', 'must be an integer'),
    (('friction', 'mu_tangential'), 0.0, 'friction.mu_tangential', 'must be > 0'),
    (('friction', 'mu_torsional'), -0.1, 'friction.mu_torsional', 'must be > 0'),
    (('friction', 'min_normal_force'), -1.0, 'friction.min_normal_force', 'must be >= 0'),
    (('grasp', 'contacts', 0, 'normal'), [0, 0, 0], r'grasp.contacts\[0\].normal',
     'must not be zero'),
    (('grasp', 'contacts', 1, 'tangent'), [-1.99626, 0.122256, 0], r'grasp.contacts\[1\].tangent',
     'is parallel to the normal'),
    (('objective',), {'weights': [1, 1]}, 'objective.weights', 'must have 4 entries'),
    (('friction', 'mu'), 0.5, 'friction.mu', 'unknown field'),
    (('grasp', 'contacts'), [], 'grasp.contacts', 'must be a non-empty list'),
    (('hand', 'torque_limits'), [10, 6, 10, 5], 'hand.torque_limits',
     "6 N m for joint 'joint2' exceeds the URDF effort limit"),
    (('hand', 'torque_limits'), 1e300, 'hand.torque_limits', 'exceeds the URDF effort limit'),
    (('hand', 'torque_limits_above_urdf'), 'yes', 'hand.torque_limits_above_urdf',
     'must be true or false'),
    (('friction', 'polygon_sides'), 10**9, 'friction.polygon_sides', 'must be at most 64'),
    (('friction', 'min_normal_force'), 10**400, 'friction.min_normal_force', 'must be finite'),
]
