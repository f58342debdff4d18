# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The joint states and commands on the wire by learnt layouts, against rclpy's own."""

from array import array

from builtin_interfaces.msg import Time
from grasp_torque_opt.ros.node.wire import JointStateLayout, Serialized
import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray

NAMES = [f'joint_{i}.0' for i in range(16)]


def joint_state(positions, velocities=(), efforts=(), names=NAMES, frame='palm', sec=1,
                nanosec=2):
    msg = JointState(name=list(names), position=array('d', positions),
                     velocity=array('d', velocities), effort=array('d', efforts))
    msg.header.stamp.sec, msg.header.stamp.nanosec, msg.header.frame_id = sec, nanosec, frame
    return msg


def test_joint_states_of_the_layout_read_as_rclpy_reads_them():
    rng = np.random.default_rng(7)
    layout = JointStateLayout()
    # The layout learnt from a message whose velocities and efforts are all zeros (a
    # driver's usual message: the values are found by marks, not by searching for them).
    first = serialize_message(joint_state(rng.random(16), np.zeros(16), np.zeros(16)))
    assert layout.read(first) is None
    assert layout.learn(first, deserialize_message(first, JointState))
    for k in range(500):
        values = [rng.standard_normal(16), rng.standard_normal(16) * (k % 2),
                  rng.standard_normal(16) * (k % 3 > 0)]
        if k % 50 == 7:
            values[0][3] = float('nan')  # read as rclpy reads it: the checks refuse it
        raw = serialize_message(joint_state(*values, sec=k, nanosec=13 * k))
        got, ref = layout.read(raw), deserialize_message(raw, JointState)
        assert got is not None, k
        stamp, names, positions, efforts = got
        assert (stamp.sec, stamp.nanosec) == (ref.header.stamp.sec, ref.header.stamp.nanosec)
        assert names == list(ref.name)
        assert positions.tobytes() == ref.position.tobytes()
        assert efforts.tobytes() == ref.effort.tobytes()
        assert type(positions) is type(ref.position)
    assert layout.read_here == 500 and layout.by_rclpy == 1


@pytest.mark.parametrize('other', [
    {'names': NAMES[:15] + ['joint_15.1']},  # a name's byte: the same length
    {'frame': 'palm2'}, {'frame': ''},
    {'efforts': ()}, {'velocities': np.zeros(16)},
    {'names': NAMES[:15], 'positions': np.ones(15)},
])
def test_a_joint_state_of_another_layout_goes_to_rclpy(other):
    layout = JointStateLayout()
    base = {'positions': np.linspace(0, 1, 16), 'efforts': np.zeros(16)}
    raw = serialize_message(joint_state(**base))
    assert layout.learn(raw, deserialize_message(raw, JointState))
    assert layout.read(serialize_message(joint_state(**{**base, **other}))) is None


def test_a_layout_is_not_learnt_from_bytes_that_are_not_rclpys_reading():
    layout = JointStateLayout()
    raw = serialize_message(joint_state(np.linspace(0, 1, 16)))
    msg = deserialize_message(raw, JointState)
    assert not layout.learn(b'\x00\x00' + raw[2:], msg)  # big-endian: not walked
    assert not layout.learn(raw, joint_state(np.linspace(0, 2, 16)))  # other values
    assert not layout.learn(raw, joint_state(np.linspace(0, 1, 16), sec=9))  # stamp
    assert not layout.learn(raw, joint_state(np.linspace(0, 1, 16), frame='base'))
    assert not layout.learn(raw, joint_state(np.linspace(0, 1, 16), names=NAMES[::-1]))
    assert not layout.learn(raw[:40], msg)  # cut short
    assert layout.read(raw) is None
    assert layout.learn(raw, msg) and layout.read(raw) is not None


def test_the_padding_of_a_layout_may_differ():
    """A message differing only in the padding (rclpy leaves it unset) is read too."""
    layout = JointStateLayout()
    raw = serialize_message(joint_state(np.linspace(0, 1, 16), frame='ab'))  # 1 pad byte
    assert layout.learn(raw, deserialize_message(raw, JointState))
    at = 4 + 8 + 4 + 3  # after the frame's length and its three bytes 'ab\0'
    other = raw[:at] + b'\xee' + raw[at + 1:]
    assert deserialize_message(other, JointState) == deserialize_message(raw, JointState)
    assert layout.read(other) is not None
    assert layout.read(raw[:at - 1] + b'c' + raw[at:]) is None  # the frame's byte: not


@pytest.mark.parametrize('n', [1, 4, 16, 22])
def test_commands_read_back_as_rclpy_reads_the_message(n):
    rng = np.random.default_rng(n)
    array_msg = Serialized(Float64MultiArray(), 'data', n)
    template = JointState(name=NAMES[:n] + [f'x{i}' for i in range(n - len(NAMES))])
    template.header.frame_id = 'palm'
    stamped = Serialized(template, 'effort', n, stamped=True)
    for k in range(50):  # the same length, read back as the message (the padding's
        # bytes are not compared: rclpy leaves them unset)
        values = array('d', rng.standard_normal(n))
        ref = Float64MultiArray(data=values)
        raw = array_msg.write(values)
        assert len(raw) == len(serialize_message(ref))
        assert deserialize_message(raw, Float64MultiArray) == ref
        stamp = Time(sec=int(rng.integers(0, 2**31)), nanosec=int(rng.integers(0, 10**9)))
        msg = JointState(name=template.name, effort=values)
        msg.header.stamp, msg.header.frame_id = stamp, 'palm'
        raw = stamped.write(values, stamp)
        assert len(raw) == len(serialize_message(msg))
        assert deserialize_message(raw, JointState) == msg
    with pytest.raises(ValueError, match='values for a command of'):
        array_msg.write(array('d', [1.0] * (n + 1)))
