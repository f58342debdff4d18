# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The input store alone: a message is kept whole or not at all; stamps; staleness."""

from cycle_inputs import joint_state
from grasp_torque_opt.control.inputs.external_wrench import WrenchReading
from grasp_torque_opt.control.inputs.gravity import GravityReading
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.inputs.store import Counters, Inputs, InputStore
from grasp_torque_opt.control.parameters.generated import CycleConfig
from grasp_torque_opt.core.exceptions import InputError
import pytest


def store(setup, **config):
    return InputStore(setup, CycleConfig(**config), Counters())


def test_a_rejected_message_changes_nothing_but_its_counter(planar):
    s = store(planar)
    names, positions = joint_state(planar)
    s.take('joint_states', JointStateReading(names, positions), 1.0)
    kept = s.inputs
    with pytest.raises(InputError, match='joint_states'):
        s.take('joint_states', JointStateReading(names, positions[:-1]), 2.0)
    assert s.inputs is kept and s.counters.rejected['joint_states'] == 1
    assert s.last_rejection.startswith('joint_states: ')


def test_gravity_is_counted_from_its_first_rejection(planar):
    s = store(planar)
    assert 'gravity' not in s.counters.rejected
    with pytest.raises(InputError):
        s.take('gravity', GravityReading('', [0.0, 0.0, float('nan')]), 0.0)
    assert s.counters.rejected['gravity'] == 1 and s.inputs == Inputs()


def test_stamps_out_of_order_are_refused_until_the_mark_is_stale(planar):
    s = store(planar, joint_state_timeout=0.1)
    names, positions = joint_state(planar)
    s.take('joint_states', JointStateReading(names, positions), 0.0, 10.0)
    with pytest.raises(InputError, match='goes backwards by 1.000000 s'):
        s.take('joint_states', JointStateReading(names, positions), 0.05, 9.0)
    s.take('joint_states', JointStateReading(names, positions), 0.2,
           9.0)  # the mark is stale: recovered
    assert s.inputs.q_time == 0.2


def test_a_stamp_ahead_of_the_clock_is_refused_and_never_marks_the_future(planar):
    s = store(planar, stamp_future_tolerance=0.5)
    names, positions = joint_state(planar)
    with pytest.raises(InputError, match='ahead of the clock'):
        s.take('joint_states', JointStateReading(names, positions), 0.0, 11.0, 10.0)
    s.take('joint_states', JointStateReading(names, positions), 0.0, 10.4, 10.0)
    s.take('joint_states', JointStateReading(names, positions), 0.01, 10.1, 10.01)  # mark was 10.0


def test_staleness_names_the_oldest_input(planar):
    s = store(planar, joint_state_timeout=0.1, wrench_timeout=0.5)
    assert s.stale(0.0) == 'no joint state yet'
    s.take('joint_states', JointStateReading(*joint_state(planar)), 0.0)
    s.take('external_wrench', WrenchReading('', [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]), 0.0)
    assert s.stale(0.05) == ''
    assert s.stale(0.2).startswith('joint_states stale')
    s.take('joint_states', JointStateReading(*joint_state(planar)), 0.55)
    assert s.stale(0.6).startswith('external_wrench stale')


def test_a_known_layout_is_held_to_every_position_rule(planar):
    # After a first state, the same names take the one-comparison path: each rule it
    # stands for still refuses, with the full check's words, and a new tolerance counts.
    s = store(planar, joint_limit_tolerance=0.1)
    names, positions = joint_state(planar)
    s.take('joint_states', JointStateReading(names, positions), 1.0)
    for value, words in ((2.15, "position of 'joint1' is 2.15, beyond its URDF limits "
                                '[-2, 2] by more than joint_limit_tolerance (0.1)'),
                         (1e6, "position of 'joint1' is 1e+06, beyond +-"),
                         (float('nan'), "position of 'joint1' is not finite"),
                         (-2.15, "position of 'joint1' is -2.15, beyond its URDF limits")):
        kept = s.inputs
        moved = [value] + list(positions[1:])
        with pytest.raises(InputError) as e:
            s.take('joint_states', JointStateReading(names, moved), 2.0)
        assert words in str(e.value)
        assert s.inputs is kept
    s.take('joint_states', JointStateReading(names, [2.05] + list(positions[1:])), 3.0)
    assert s.inputs.q[0] == 2.05
    s.config = CycleConfig(joint_limit_tolerance=0.2)
    s.take('joint_states', JointStateReading(names, [2.15] + list(positions[1:])), 4.0)
    assert s.inputs.q[0] == 2.15
