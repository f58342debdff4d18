# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The node's own wait-set loop: rclpy's single-threaded executor, lighter per message.

:class:`WaitSetExecutor` is rclpy's ``SingleThreadedExecutor`` (same wait set, same
order of callbacks, the same callback groups) with four costs of its wait taken out,
which at a thousand joint states a second were a large share of the node's CPU beside
an echo node's (docs/benchmarks.md, "The node measured"):

- rclpy's ``spin_once(timeout_sec)`` made a new rcl timer for every wait, only to tell a
  timeout; here the wait's own return (nothing ready by the deadline) tells it;
- rclpy made a new ``WaitSet`` for every wait; here one is kept while the number of
  entities is the same (cleared and filled again before each wait, as rcl wants);
- rclpy ran every callback as a ``Task`` of a coroutine, and triggered the executor's own
  guard condition twice after it, which woke the next wait for nothing (a second wait
  per joint state); here a subscription's or a timer's plain-function callback is called
  directly, within its callback group's ``beginning_execution`` / ``ending_execution``;
- rclpy's ready check looked each entity's handle pointer up in a list; here in a set.

Everything else goes the rclpy way (a ``Task`` from ``_make_handler``): services
(``~/solve`` is a coroutine), clients, guard conditions, waitables (QoS events), and a
coroutine callback on a subscription or timer; tasks in progress are resumed first.
"""

from __future__ import annotations

from contextlib import ExitStack
import inspect
import time
from typing import Any, Callable

from rclpy.exceptions import InvalidHandle
from rclpy.executors import (
    ConditionReachedException,
    ExternalShutdownException,
    ShutdownException,
    SingleThreadedExecutor,
    TimeoutException,
    TimeoutObject,
)
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.subscription import Subscription
from rclpy.utilities import timeout_sec_to_nsec
from rclpy.waitable import NumberOfEntities


class _Direct:
    """A callback run at once, with the two methods rclpy's spin_once asks of a Task."""

    __slots__ = ('run',)

    def __init__(self, run: Callable[[], None]) -> None:
        self.run = run

    def __call__(self) -> None:
        self.run()

    def exception(self) -> None:
        """Give None: an exception of the callback was raised by ``__call__`` itself."""
        return None

    def result(self) -> None:
        """Give None, as a Task of a callback that returned."""
        return None


def _plain(entity: Any) -> bool:
    """Tell whether an entity's callback is a plain function (not a coroutine function)."""
    plain = getattr(entity, '_gto_plain', None)
    if plain is None or plain[0] is not entity.callback:
        plain = (entity.callback, not inspect.iscoroutinefunction(entity.callback))
        entity._gto_plain = plain
    return plain[1]


def _run_subscription(sub: Subscription) -> None:
    """Take one message of ``sub`` and call its callback (as rclpy's Task would)."""
    group = sub.callback_group
    if not group.beginning_execution(sub):
        return
    try:
        with sub.handle:
            taken = sub.handle.take_message(sub.msg_type, sub.raw)
        if taken is None:
            return
        if sub._callback_type is Subscription.CallbackType.MessageOnly:
            sub.callback(taken[0])
        else:
            sub.callback(*taken)
    except InvalidHandle:
        pass  # destroyed since the wait: nothing to take
    finally:
        group.ending_execution(sub)


def _run_timer(tmr: Any) -> None:
    """Call a timer that is due (rclpy's check of a cancelled timer kept) and its callback."""
    group = tmr.callback_group
    if not group.beginning_execution(tmr):
        return
    try:
        with tmr.handle:
            if not tmr.handle.is_timer_ready():
                return
            tmr.handle.call_timer()
        tmr.callback()
    except InvalidHandle:
        pass
    finally:
        group.ending_execution(tmr)


class _Entities:
    """
    What the waits wait on: the nodes' entities entered (kept alive), and a wait set.

    Made again when an entity is made or destroyed (rclpy's node wakes its executor by
    triggering the executor's guard condition), a node is added or removed, or while a
    coroutine callback is in progress (its callback group may bar others from the wait).
    """

    KINDS = ('timer', 'subscription', 'guard_condition', 'client', 'service')

    def __init__(self, executor: WaitSetExecutor, nodes: list) -> None:
        can = executor.can_execute
        self.nodes = tuple(nodes)
        self.stack = ExitStack()
        #: Per kind, the (handle pointer, entity, node) waited on.
        self.by_kind: dict[str, list] = {k: [] for k in self.KINDS}
        #: The nodes' entities as (kind, pointer, entity, node) in the order rclpy's
        #: executor looks at them: node by node, timers, subscriptions, guard conditions,
        #: clients, services, each in the order it was made.
        self.order: list[tuple[str, int, Any, Any]] = []
        self.waitables: list[tuple[Any, Any]] = []
        stack = self.stack
        stack.enter_context(executor._context.handle)
        for node in nodes:
            for kind, entities in zip(self.KINDS, (node.timers, node.subscriptions,
                                                   node.guards, node.clients, node.services)):
                for entity in filter(can, entities):
                    try:
                        stack.enter_context(entity.handle)
                    except InvalidHandle:
                        continue
                    if kind == 'guard_condition' and entity._executor_triggered:
                        entity.trigger()  # triggered but not handled: again (as rclpy)
                    self.by_kind[kind].append((entity.handle.pointer, entity, node))
                    self.order.append((kind, entity.handle.pointer, entity, node))
            for w in filter(can, node.waitables):
                try:
                    stack.enter_context(w)
                except InvalidHandle:
                    continue
                self.waitables.append((w, node))
        for gc in (executor._guard, executor._sigint_gc):
            stack.enter_context(gc.handle)
            self.by_kind['guard_condition'].append((gc.handle.pointer, gc, None))
        n = NumberOfEntities()
        for w, _ in self.waitables:
            n += w.get_num_entities()
        b = self.by_kind
        self.wait_set = _rclpy.WaitSet(
            len(b['subscription']) + n.num_subscriptions,
            len(b['guard_condition']) + n.num_guard_conditions, len(b['timer']) + n.num_timers,
            len(b['client']) + n.num_clients, len(b['service']) + n.num_services, n.num_events,
            executor._context.handle)

    def close(self) -> None:
        """Let the entities go (a destroyed one is freed now)."""
        self.stack.close()


class WaitSetExecutor(SingleThreadedExecutor):
    """rclpy's SingleThreadedExecutor with a lighter wait (module docstring)."""

    def __init__(self, **kwargs: Any) -> None:
        """Take rclpy's executor arguments (``context``)."""
        super().__init__(**kwargs)
        self._entities: _Entities | None = None
        self._changed = True  # an entity made or destroyed since the entities were taken

    def wake(self) -> None:
        """Wake the wait (rclpy's nodes call it when an entity is made or destroyed)."""
        self._changed = True
        super().wake()

    def shutdown(self, timeout_sec: float | None = None) -> bool:
        """Shut down as rclpy's executor does, and let the entities go."""
        done = super().shutdown(timeout_sec)
        self._drop()
        return done

    def _drop(self) -> None:
        if self._entities is not None:
            self._entities.close()
            self._entities = None

    def _tasks_in_progress(self, nodes: list):
        """Yield the tasks in progress (a coroutine callback waiting), as rclpy does first."""
        with self._tasks_lock:
            tasks = list(self._tasks)
        if not tasks:
            return
        for task, entity, node in reversed(tasks):
            if not task.executing() and not task.done() and (node is None or node in nodes):
                yield task, entity, node
        with self._tasks_lock:
            self._tasks = [t for t in self._tasks if not t[0].done() and not t[0].cancelled()]

    def _current(self, nodes: list) -> _Entities:
        """Give the entities to wait on, made again when they may have changed."""
        e = self._entities
        with self._tasks_lock:
            busy = bool(self._tasks)
        if e is None or busy or self._changed or e.nodes != tuple(nodes):
            self._drop()
            self._changed = False  # before taking them: a change meanwhile is seen next
            self._entities = e = _Entities(self, nodes)
        return e

    def _wait(self, e: _Entities, timeout_nsec: int) -> tuple[dict, list]:
        """Fill the wait set, wait; give the ready pointers by kind, and the ready waitables."""
        ws = e.wait_set
        ws.clear_entities()
        for kind, add in (('subscription', ws.add_subscription), ('client', ws.add_client),
                          ('service', ws.add_service), ('timer', ws.add_timer),
                          ('guard_condition', ws.add_guard_condition)):
            for _, entity, _ in e.by_kind[kind]:
                add(entity.handle)
        waitables = []
        for w, node in e.waitables:
            try:
                w.add_to_wait_set(ws)
                waitables.append((w, node))
            except InvalidHandle:  # destroyed from another thread since: taken again next
                self._changed = True
        ws.wait(timeout_nsec)
        if self._is_shutdown:
            raise ShutdownException()
        if not self._context.ok():
            raise ExternalShutdownException()
        ready = {kind: set(ws.get_ready_entities(kind)) for kind in _Entities.KINDS}
        ready_waitables = [(w, node) for w, node in waitables if w.is_ready(ws)]
        guards = ready['guard_condition']
        for ptr, gc, _ in e.by_kind['guard_condition']:  # auto-taken: marked first
            if ptr in guards:
                gc._executor_triggered = True
        return ready, ready_waitables

    def _ready(self, e: _Entities, ready: dict, waitables: list):
        """Yield the ready work in rclpy's order: waitables, then node by node (``order``)."""
        for wt, node in waitables:
            if wt.callback_group.can_execute(wt):
                yield self._make_handler(wt, node, self._take_waitable), wt, node
        take = {'guard_condition': self._take_guard_condition, 'client': self._take_client,
                'service': self._take_service}
        any_ready = set().union(*(ready[k] for k in ('timer', 'subscription', 'client',
                                                     'service')))
        for kind, ptr, entity, node in e.order:
            if kind == 'guard_condition':
                if not entity._executor_triggered:
                    continue
            elif ptr not in any_ready:
                continue
            if not entity.callback_group.can_execute(entity):
                continue
            if kind == 'timer':
                if _plain(entity):
                    yield _Direct(lambda t=entity: _run_timer(t)), entity, node
                elif entity.handle.is_timer_ready():
                    yield self._make_handler(entity, node, self._take_timer), entity, node
            elif kind == 'subscription':
                yield (_Direct(lambda s=entity: _run_subscription(s)) if _plain(entity)
                       else self._make_handler(entity, node, self._take_subscription)
                       ), entity, node
            else:
                yield self._make_handler(entity, node, take[kind]), entity, node

    def _wait_for_ready_callbacks(self, timeout_sec: Any = None, nodes: list | None = None,
                                  condition: Callable[[], bool] = lambda: False):
        """Yield ready callbacks as rclpy's executor does, with the lighter wait."""
        seconds = timeout_sec.timeout if isinstance(timeout_sec, TimeoutObject) else timeout_sec
        timeout_nsec = timeout_sec_to_nsec(seconds)
        deadline = None if timeout_nsec < 0 else time.monotonic_ns() + timeout_nsec
        yielded = False
        while not yielded and not self._is_shutdown and not condition():
            use = self.get_nodes() if nodes is None else nodes
            for work in self._tasks_in_progress(use):
                yielded = True
                yield work
            wait = -1 if deadline is None else max(0, deadline - time.monotonic_ns())
            entities = self._current(use)
            ready, waitables = self._wait(entities, wait)
            for work in self._ready(entities, ready, waitables):
                yielded = True
                yield work
            if not yielded and deadline is not None and time.monotonic_ns() >= deadline:
                raise TimeoutException()
        if self._is_shutdown:
            raise ShutdownException()
        if condition():
            raise ConditionReachedException()
