# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The bundled params files apply under any node name and namespace (keyed /**:)."""

from conftest import CONFIG
from grasp_torque_opt.ros.lifecycle_node import GraspTorqueLifecycleNode
from grasp_torque_opt.ros.node import GraspTorqueNode
import pytest
import rclpy
from rclpy.lifecycle import TransitionCallbackReturn
from ros_harness import DOMAIN
import yaml

FILES = sorted(CONFIG.glob('*_node.yaml'))


def flat(params, prefix=''):
    """Give a params file's nested maps (imu: {enabled: ...}) as dotted names."""
    out = {}
    for k, v in params.items():
        out.update(flat(v, f'{prefix}{k}.') if isinstance(v, dict) else {f'{prefix}{k}': v})
    return out


@pytest.mark.parametrize('path', FILES, ids=[p.name for p in FILES])
@pytest.mark.parametrize('remap', [[], ['-r', '__node:=right_hand_torques'],
                                   ['-r', '__ns:=/right_hand']])
@pytest.mark.parametrize('kind', [GraspTorqueNode, GraspTorqueLifecycleNode],
                         ids=['plain', 'managed'])
def test_every_parameter_of_the_file_applies_whatever_the_name(path, remap, kind):
    params = next(iter(yaml.safe_load(path.read_text()).values()))['ros__parameters']
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=DOMAIN)
    try:
        node = kind(context=context,
                    cli_args=['--ros-args', '--params-file', str(path), *remap])
        try:
            if kind is GraspTorqueLifecycleNode:  # it loads the file's scenario at configure
                assert node.trigger_configure() == TransitionCallbackReturn.SUCCESS
            for name, value in flat(params).items():
                got = node.get_parameter(name).value
                assert (list(got) if isinstance(value, list) else got) == value, name
            if remap:
                assert 'right_hand' in node.get_fully_qualified_name()
        finally:
            node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
