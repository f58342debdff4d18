# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The node's own wait-set loop (grasp_torque_opt.ros.node.waitset) on real rclpy entities.

What rclpy's executor does, it does: a subscription's messages, a timer, a coroutine
service answered through rclpy's Task, a client's future, an entity destroyed between
spins, a timeout with nothing ready. What it does differently: a plain callback runs
without a Task (rclpy's executor makes one per callback, and wakes its next wait for it).
"""

import os

from grasp_torque_opt.ros.node.waitset import WaitSetExecutor
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.task import Future
from ros_domains import domain
from std_msgs.msg import Int32
from std_srvs.srv import Trigger

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'


@pytest.fixture()
def context():
    ctx = rclpy.Context()
    rclpy.init(context=ctx, domain_id=domain('in_process'))
    yield ctx
    rclpy.try_shutdown(context=ctx)


def spin_until(executor, predicate, timeout=5.0):
    import time

    end = time.monotonic() + timeout
    while not predicate() and time.monotonic() < end:
        executor.spin_once(timeout_sec=0.05)
    return predicate()


@pytest.fixture()
def pair(context):
    """Two nodes on one WaitSetExecutor; closed after the test."""
    a = rclpy.create_node('waitset_a', context=context)
    b = rclpy.create_node('waitset_b', context=context)
    executor = WaitSetExecutor(context=context)
    executor.add_node(a)
    executor.add_node(b)
    yield a, b, executor
    executor.shutdown()
    a.destroy_node()
    b.destroy_node()


def test_messages_timers_and_a_destroyed_subscription(pair):
    a, b, executor = pair
    got, ticks = [], []
    pub = a.create_publisher(Int32, 'numbers', 10)
    sub = b.create_subscription(Int32, 'numbers', lambda m: got.append(m.data), 10)
    b.create_timer(0.01, lambda: ticks.append(1))
    assert spin_until(executor, lambda: b.count_publishers('numbers') and
                      a.count_subscribers('numbers'))
    for k in range(5):
        pub.publish(Int32(data=k))
    assert spin_until(executor, lambda: len(got) == 5 and len(ticks) >= 3)
    assert got == list(range(5))
    b.destroy_subscription(sub)  # made again: the destroyed one is neither waited nor called
    pub.publish(Int32(data=9))
    for _ in range(10):
        executor.spin_once(timeout_sec=0.01)
    assert got == list(range(5))


def test_a_plain_callback_runs_without_a_task(context):
    """A plain callback: a Task of rclpy's executor; called by the wait-set loop."""
    for kind, tasks in ((SingleThreadedExecutor, 1), (WaitSetExecutor, 0)):
        node = rclpy.create_node(f'waitset_{kind.__name__.lower()}', context=context)
        executor = kind(context=context)
        executor.add_node(node)
        got = []
        pub = node.create_publisher(Int32, 'once', 10)
        node.create_subscription(Int32, 'once', got.append, 10)
        assert spin_until(executor, lambda: node.count_subscribers('once') == 1)
        before = len(executor._tasks)
        pub.publish(Int32(data=1))
        assert spin_until(executor, lambda: got)
        assert len(executor._tasks) - before == tasks, kind
        executor.shutdown()
        node.destroy_node()


def test_a_coroutine_service_and_a_client(pair):
    """~/solve's way: an async service awaiting a future done later; a client's future."""
    a, b, executor = pair
    later = []

    async def answer(request, response):
        done = Future(executor=executor)
        later.append(done)
        await done
        response.success, response.message = True, 'answered'
        return response

    a.create_service(Trigger, 'ask', answer)
    client = b.create_client(Trigger, 'ask')
    assert spin_until(executor, client.service_is_ready)
    future = client.call_async(Trigger.Request())
    assert spin_until(executor, lambda: later)
    assert not future.done()  # the service waits; the executor goes on
    later[0].set_result(None)
    assert spin_until(executor, future.done)
    assert future.result().message == 'answered'


def test_spin_once_returns_on_its_timeout(pair):
    _, _, executor = pair
    executor.spin_once(timeout_sec=0.0)
    executor.spin_once(timeout_sec=0.02)  # nothing ready: returns (no timer made for it)
