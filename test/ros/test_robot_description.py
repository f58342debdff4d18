# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The URDF from the ``robot_description`` topic, as robot_state_publisher publishes it.

A publisher in another context (another DDS participant, as another process would
be) publishes the URDF once, reliable and transient local; the node takes it at
start (the plain node) or at configure (the managed node), within
``robot_description_timeout``.
"""

import threading
import time

from conftest import ALLEGRO, PLANAR
from cycle_inputs import joint_state
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import MAX_URDF_BYTES
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.ros.node import GraspTorqueNode, URDF_QOS
from lifecycle_msgs.msg import Transition
import numpy as np
import pytest
from rcl_interfaces.msg import Log
import rclpy
from rclpy.parameter import Parameter
from ros_harness import DOMAIN, Harness, LifecycleHarness
from std_msgs.msg import String
from test_name_map import NAME_MAP, renamed, write_renamed_urdf

PLANAR_URDF = PLANAR.parent.parent / 'urdf' / 'planar_two_finger.urdf'


class Publisher:
    """robot_description published from a context of its own (latched: transient local)."""

    def __init__(self, topic: str = 'robot_description'):
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=DOMAIN)
        self.node = rclpy.create_node('robot_state_publisher', context=self.context)
        self.pub = self.node.create_publisher(String, topic, URDF_QOS)

    def publish(self, urdf: str) -> None:
        self.pub.publish(String(data=urdf))

    def close(self) -> None:
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


@pytest.fixture
def publisher():
    p = Publisher()
    yield p
    p.close()


def planar_urdf_named(name: str) -> str:
    """Give the planar hand's URDF under another robot name (diagnostics' hardware_id)."""
    text = PLANAR_URDF.read_text()
    assert '<robot name="planar_two_finger"' in text
    return text.replace('<robot name="planar_two_finger"', f'<robot name="{name}"')


def test_the_plain_node_takes_the_urdf_published_before_it_started(planar, publisher):
    publisher.publish(planar_urdf_named('planar_from_the_topic'))
    h = Harness(PLANAR, robot_description_topic='robot_description')
    try:
        h.send_joint_state(*joint_state(planar))
        np.testing.assert_allclose(h.next_command(), solve(planar).tau, atol=1e-9)
        assert h.spin_until(lambda: h.diagnostics, 2.0)
        assert h.diagnostics[-1]['_hardware_id'] == 'planar_from_the_topic'
    finally:
        h.close()


def test_the_parameter_wins_over_the_topic(planar, publisher):
    publisher.publish(planar_urdf_named('planar_from_the_topic'))
    h = Harness(PLANAR, robot_description=str(PLANAR_URDF),
                robot_description_topic='robot_description')
    try:
        assert h.spin_until(lambda: h.diagnostics, 2.0)
        assert h.diagnostics[-1]['_hardware_id'] == 'planar_two_finger'
    finally:
        h.close()


def start_plain(**params):
    ctx = rclpy.Context()
    rclpy.init(context=ctx, domain_id=DOMAIN)
    overrides = [Parameter('scenario', value=str(PLANAR)),
                 *(Parameter(k, value=v) for k, v in params.items())]
    try:
        GraspTorqueNode(context=ctx, parameter_overrides=overrides).destroy_node()
    finally:
        rclpy.try_shutdown(context=ctx)


def test_no_urdf_on_the_topic_ends_the_wait_in_bounded_time():
    t0 = time.monotonic()
    with pytest.raises(InputError, match=r'^robot_description_topic: no URDF on '
                       r'/no_robot_here within 0\.5 s \(robot_description_timeout\)'):
        start_plain(robot_description_topic='no_robot_here', robot_description_timeout=0.5)
    assert time.monotonic() - t0 < 10.0  # 0.5 s and the node's start, on a loaded machine


def test_a_urdf_message_too_large_is_refused_by_its_length(publisher):
    publisher.publish('<robot name="big">' + ' ' * (MAX_URDF_BYTES + 1000) + '</robot>')
    with pytest.raises(InputError, match=r'^robot_description_topic: the URDF on '
                       r'/robot_description is \d+ bytes serialized, larger than a URDF '
                       r'may be \(2097152 bytes\)$'):
        start_plain(robot_description_topic='robot_description')


def test_a_bad_topic_name_is_refused():
    with pytest.raises(InputError, match=r'^robot_description_topic: Invalid topic name'):
        start_plain(robot_description_topic='robot description')


def test_configure_waits_for_the_urdf_then_cleanup_takes_the_next_one(planar, allegro,
                                                                      publisher, tmp_path):
    h = LifecycleHarness(PLANAR, robot_description_topic='robot_description',
                         robot_description_timeout=30.0)
    try:
        # Published while configure waits (it holds the node's executor meanwhile).
        timer = threading.Timer(0.5, publisher.publish,
                                args=(planar_urdf_named('planar_from_the_topic'),))
        timer.start()
        t0 = time.monotonic()
        assert h.transition(Transition.TRANSITION_CONFIGURE, timeout=40.0)
        assert time.monotonic() - t0 >= 0.4
        timer.join()
        assert h.transition(Transition.TRANSITION_ACTIVATE)
        assert h.spin_until(h.subscribed, 10.0)
        h.send_joint_state(*joint_state(planar))
        np.testing.assert_allclose(h.next_command(), solve(planar).tau, atol=1e-9)
        # Cleanup releases the hand; another hand published, another scenario set: the
        # next configure takes them, with that hand's defaults (16 joints, renamed).
        assert h.transition(Transition.TRANSITION_DEACTIVATE)
        assert h.transition(Transition.TRANSITION_CLEANUP)
        assert h.node.controller is None and h.node.root.parameters.value('torque_limits') is None
        urdf = write_renamed_urdf(tmp_path).read_text()
        publisher.publish(urdf)
        results = h.set_parameters(scenario=str(ALLEGRO), name_map=NAME_MAP)
        assert all(r.successful for r in results)
        assert h.transition(Transition.TRANSITION_CONFIGURE, timeout=40.0)
        joints = list(h.node.get_parameter('joints').value)
        assert joints == [renamed(j) for j in allegro.hand.joints]
        assert len(h.node.get_parameter('torque_limits').value) == 16
        # The same grasp as the core's on this URDF, bound to the mapped scenario.
        ref = solve(GraspSetup.from_scenario(
            load_scenario(ALLEGRO, dict(e.split('=') for e in NAME_MAP)), urdf))
        assert ref.optimal
        assert h.transition(Transition.TRANSITION_ACTIVATE)
        assert h.spin_until(h.subscribed, 10.0)
        names, pos = joint_state(allegro)
        h.send_joint_state([renamed(n) for n in names], pos)
        np.testing.assert_allclose(h.next_command(), ref.tau, atol=1e-9)
    finally:
        h.close()


def test_configure_gives_up_in_bounded_time_and_the_node_still_answers():
    h = LifecycleHarness(PLANAR, robot_description_topic='no_robot_here',
                         robot_description_timeout=0.5)
    try:
        t0 = time.monotonic()
        assert not h.transition(Transition.TRANSITION_CONFIGURE)
        assert time.monotonic() - t0 < 10.0
        assert h.state() == 'unconfigured'
        reason = ('configure failed: robot_description_topic: no URDF on /no_robot_here within '
                  '0.5 s (robot_description_timeout)')
        assert h.spin_until(lambda: any(m.level == Log.ERROR and m.msg.startswith(reason)
                                        for m in h.logs), 5.0)
    finally:
        h.close()
