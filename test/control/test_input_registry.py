# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The node's inputs as plug-ins: each one the protocol, the store's one path, the ROS table."""

import dataclasses

from cycle_inputs import fresh, joint_state
from grasp_torque_opt.control.inputs.base import NodeInput, QOS
from grasp_torque_opt.control.inputs.external_wrench import WrenchReading
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.inputs.object_pose import PoseReading
from grasp_torque_opt.control.inputs.registry import REGISTRY, SOURCES
from grasp_torque_opt.control.inputs.store import Inputs
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.object_geometry import object_pose
import numpy as np
import pytest

FIELDS = {f.name for f in dataclasses.fields(Inputs)}


@pytest.mark.parametrize('name', list(REGISTRY))
def test_every_input_implements_the_protocol(name):
    given = REGISTRY[name]
    assert given.name == name and given.qos in QOS and given.message.count('/msg/') == 1
    for member in NodeInput.__protocol_attrs__ if hasattr(NodeInput, '__protocol_attrs__') \
            else ('check', 'keep', 'stamp_timeout', 'stale', 'name', 'message', 'qos',
                  'counted', 'enabled', 'timeout'):
        assert hasattr(given, member), f'{name} lacks {member}'


def test_the_counted_inputs_are_the_three_always_there():
    assert SOURCES == ('joint_states', 'contacts', 'external_wrench')


def test_one_path_keeps_an_input_and_counts_a_rejection(planar):
    ctrl = fresh(planar)
    ctrl.take('joint_states', JointStateReading(*joint_state(planar)), 1.0)
    ctrl.take('external_wrench', WrenchReading('', [0.0, -1.0, 0.0], [0.0, 0.0, 0.0]), 1.0)
    kept = ctrl.store.inputs
    assert set(kept.__dict__) <= FIELDS and kept.wrench[1][1] == -1.0 and kept.wrench_time == 1.0
    with pytest.raises(InputError, match='external_wrench.wrench.force'):
        ctrl.take('external_wrench', WrenchReading('', [float('nan')] * 3, [0.0] * 3), 2.0)
    assert ctrl.store.inputs is kept and ctrl.counters.rejected['external_wrench'] == 1


def test_an_object_pose_out_of_order_is_refused_by_its_own_timeout(allegro):
    """The stamp rule had no timeout for object_pose: a late pose raised KeyError."""
    ctrl = fresh(allegro)
    ctrl.store.scenario_pose = object_pose(allegro.object_origin, np.zeros(3))
    ctrl.take('joint_states', JointStateReading(*joint_state(allegro)), 1.0)
    pose = allegro.object_origin.tolist()
    ctrl.take('object_pose', PoseReading('', pose, [0.0, 0.0, 0.0, 1.0]), 1.0, 10.0)
    with pytest.raises(InputError, match='object_pose.header.stamp: goes backwards'):
        ctrl.take('object_pose', PoseReading('', pose, [0.0, 0.0, 0.0, 1.0]), 1.1, 9.0)
    assert ctrl.counters.rejected['object_pose'] == 1
