# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""The node's parameters over ROS, from the schema: descriptors and every validator known."""

from grasp_torque_opt.control.parameters.validators import BUILT_IN
from grasp_torque_opt.ros.node.parameters import (
    descriptor,
    FIXED_WHILE_CONFIGURED,
    PARAMETERS,
    SCENARIO_PARAMETERS,
)


def test_every_validator_the_schema_names_is_known_to_the_node():
    named = {v for s in PARAMETERS.specs.values() for v, _ in s.validation}
    assert named <= set(BUILT_IN) | set(PARAMETERS.validators)


def test_descriptors_carry_unit_range_choices_and_read_only():
    d = descriptor('polygon_sides')
    assert (d.integer_range[0].from_value, d.integer_range[0].to_value) == (3, 64)
    d = descriptor('joint_state_timeout')
    assert d.description.endswith('[s]') and d.floating_point_range[0].to_value == 10.0
    assert descriptor('fault_policy').additional_constraints == 'one of: hold, zero'
    assert descriptor('solver.backend').additional_constraints == \
        'one of: proxsuite, daqp, quadprog'
    assert descriptor('joints').read_only and not descriptor('joints', managed=True).read_only
    assert descriptor('joints', managed=True).additional_constraints == FIXED_WHILE_CONFIGURED


def test_the_scenario_parameters_are_the_schemas():
    assert set(SCENARIO_PARAMETERS) == {
        'joints', 'torque_limits_above_urdf', 'object_origin', 'mu_tangential',
        'mu_torsional', 'polygon_sides', 'min_normal_force', 'torque_limits', 'weights',
        'friction_margin', 'objective', 'gravity'}
