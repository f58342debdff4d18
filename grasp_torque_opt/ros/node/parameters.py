# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The node's parameters over ROS: declared, described and checked from the one schema.

The schema is ``grasp_torque_opt/control/grasp_torque_node_parameters.yaml``
(:mod:`grasp_torque_opt.control.parameters.schema`); here it gets what needs ROS: the
``ParameterDescriptor`` of each entry, the topic-name check, the types rclpy declares
a parameter with while it has no value, and the snapshot of the values the node runs
with.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from grasp_torque_opt.control.parameters.schema import ParamSpec, SCHEMA
from grasp_torque_opt.control.parameters.validators import Context
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import Hand, MAX_TORQUE_LIMIT
from grasp_torque_opt.core.scenario import Scenario
import numpy as np
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.exceptions import InvalidTopicNameException
from rclpy.parameter import Parameter
from rclpy.validate_topic_name import validate_topic_name

#: The constraint a read-only parameter of the plain node has in the managed node.
FIXED_WHILE_CONFIGURED = 'fixed while configured: set it while unconfigured, then configure'
#: rclpy's types of the schema's types (to declare a parameter without a value).
ROS_TYPES = {'string': Parameter.Type.STRING, 'double': Parameter.Type.DOUBLE,
             'int': Parameter.Type.INTEGER, 'bool': Parameter.Type.BOOL,
             'string_array': Parameter.Type.STRING_ARRAY,
             'double_array': Parameter.Type.DOUBLE_ARRAY}


def validate_topic(name: str, value: Any, ctx: Context) -> str:
    """Refuse an invalid ROS topic name ('': none, accepted)."""
    if not value:
        return ''
    try:
        validate_topic_name(value)
    except InvalidTopicNameException as e:
        return str(e).splitlines()[0]
    return ''


#: The node's parameters: the schema with its ROS validators. ``PARAMETERS[name]`` is
#: the entry (:class:`~grasp_torque_opt.control.parameters.schema.ParamSpec`).
PARAMETERS = SCHEMA.with_validators(topic_name=validate_topic)
#: The parameters whose defaults come from the scenario (and its hand): the managed node
#: declares them by type until configure fills them in.
SCENARIO_PARAMETERS = {s.name: ROS_TYPES[s.type] for s in PARAMETERS.specs.values()
                       if s.from_scenario is not None}
#: Parameters declared without a value and left so unless given (``name_map``: ROS
#: parameters cannot hold an empty list of a known type).
UNSET_PARAMETERS = {s.name: ROS_TYPES[s.type] for s in PARAMETERS.specs.values()
                    if s.unset is not None}


def descriptor(name: str, managed: bool = False) -> ParameterDescriptor:
    """
    Build the ParameterDescriptor of a parameter from its schema entry.

    Args:
        name: the parameter.
        managed: for the managed node, where a parameter that is read-only in the
            plain node can be set while unconfigured (and is refused while configured).
    """
    spec: ParamSpec = PARAMETERS[name]
    unit = '' if spec.unit == '-' else f' [{spec.unit}]'
    d = ParameterDescriptor(name=name, description=spec.description + unit,
                            read_only=spec.read_only and not managed)
    constraints = []
    if spec.choices is not None:
        constraints.append('one of: ' + ', '.join(spec.choices))
    if managed and spec.read_only:
        constraints.append(FIXED_WHILE_CONFIGURED)
    d.additional_constraints = '; '.join(constraints)
    if spec.bounds is not None:
        low, high = spec.bounds
        if spec.type == 'int':
            d.integer_range = [IntegerRange(from_value=low, to_value=high, step=1)]
        else:
            d.floating_point_range = [FloatingPointRange(from_value=float(low),
                                                         to_value=float(high), step=0.0)]
    return d


def scenario_defaults(scenario: Scenario, setup: GraspSetup) -> dict[str, Any]:
    """
    Give the defaults of :data:`SCENARIO_PARAMETERS` from a scenario bound to its hand.

    Each is read where its entry's ``from_scenario`` field says
    (:meth:`~grasp_torque_opt.control.parameters.schema.Schema.scenario_defaults`).
    """
    return PARAMETERS.scenario_defaults({'scenario': scenario, 'setup': setup})


def limit_bounds(hand: Hand, above_urdf: bool) -> np.ndarray:
    """
    Give the largest torque limit per joint [N m].

    The URDF's effort limit, the scenario's limit where the URDF gives none;
    MAX_TORQUE_LIMIT if allowed above.
    """
    if above_urdf:
        return np.full(hand.m, MAX_TORQUE_LIMIT)
    effort = hand.effort_limits
    return np.where(np.isfinite(effort), effort, hand.torque_limits)


def hand_context(hand: Hand, above_urdf: bool) -> Context:
    """Give the checks' context once a hand is loaded: its joints and torque bounds."""
    return Context(m=hand.m, joints=tuple(hand.joints),
                   torque_bounds=limit_bounds(hand, above_urdf))


def check_all(values: Mapping[str, Any], ctx: Context) -> None:
    """
    Check every parameter that has a value, in declaration order.

    Raises:
        InputError: the first one refused, named.
    """
    for name in PARAMETERS:
        if values.get(name) is not None:
            PARAMETERS.check(name, values[name], ctx)
