# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
``~/solve``: one solve on demand, on a snapshot of the inputs, off the control loop.

Requests are queued for one worker thread with a controller of its own (its own
Pinocchio data and solver workspace, cold, in slices); beyond MAX_PENDING_SOLVES
queued, a request is answered "busy" at once: every request gets an answer, in
bounded memory. The answer is the CLI's JSON with the command and g(q).
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
import threading
import time
from typing import Any, TYPE_CHECKING

from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.core.report import solution_dict, strict_json
from grasp_torque_opt.ros import realtime
from grasp_torque_opt.ros.node.qos import SERVICE_QOS
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.task import Future
from std_srvs.srv import Trigger

if TYPE_CHECKING:
    from grasp_torque_opt.ros.node.root import GraspTorque

#: Solves the service queues for its worker (each a snapshot of the inputs); a request
#: beyond them is answered "busy" at once. (100 before: three bursts of 1,000 calls kept
#: the worker solving for seconds and took the command rate from 900 to 69-190 Hz.)
MAX_PENDING_SOLVES = 10
#: The worker's share of the time: after a solve of t seconds it rests t * (1 / share - 1),
#: so that the control loop, which shares the interpreter lock with it, keeps the rest.
WORKER_SHARE = 0.25


class SolveService:
    """The ``~/solve`` service and its worker, for the node's lifetime."""

    def __init__(self, root: GraspTorque) -> None:
        """Belong to ``root``: its lock and controllers."""
        self.root = root
        self.worker: ThreadPoolExecutor | None = None
        self.controller: TorqueController | None = None  # made by the root
        self.pending = 0
        self.busy_answers = 0
        self._stopping = threading.Event()  # ends a rest at shutdown

    def start(self) -> None:
        """
        Make ``~/solve`` and its worker thread.

        The managed node keeps them while unconfigured too (answering that it cannot
        solve): a request still being solved at cleanup is answered on a service that
        still exists (rclpy's executor raises out of spin when a coroutine answers on a
        destroyed one).
        """
        # The worker starts from the executor's thread, maybe SCHED_FIFO: back to normal.
        self.worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix='solve_service',
                                         initializer=realtime.normal_scheduling)
        self.pending = 0
        self._stopping.clear()
        # A group of its own: in the node's default (mutually exclusive) group, each call
        # held every callback of the node, the control loop's included, until its solve
        # was done; reentrant, so that requests are taken (and answered "busy") meanwhile.
        self.root.node.create_service(Trigger, '~/solve', self.on_solve,
                                      qos_profile=SERVICE_QOS,
                                      callback_group=ReentrantCallbackGroup())

    def shutdown(self) -> None:
        """Stop the worker, dropping the requests still queued."""
        if self.worker is not None:
            self._stopping.set()
            self.worker.shutdown(wait=True, cancel_futures=True)

    async def on_solve(self, request: Trigger.Request, response: Trigger.Response
                       ) -> Trigger.Response:
        """
        Queue one solve for the worker, or answer "busy" at once.

        Runs in the executor's thread only, as does the count.
        """
        if self.pending >= MAX_PENDING_SOLVES:
            self.busy_answers += 1
            response.success = False
            response.message = (f'busy: {self.pending} solves queued (at most '
                                f'{MAX_PENDING_SOLVES}); call again later')
            return response
        root = self.root
        with root.lock:
            worker, ctrl = self.worker, self.controller
            inputs = root.controller.inputs if root.controller is not None else None
        if worker is None or ctrl is None:
            response.success = False
            response.message = 'cannot solve: not configured (lifecycle state unconfigured)'
            return response
        self.pending += 1
        try:
            done = Future(executor=root.node.executor)
            done.add_done_callback(lambda _: None)  # completion wakes the executor
            worker.submit(self.solve, inputs, root.inputs.now(), done, ctrl)
            await done
        finally:
            self.pending -= 1
        response.success, response.message = done.result()
        return response

    def solve(self, inputs: Any, now: float, done: Future,
              ctrl: TorqueController | None = None) -> None:
        """
        Solve once on a snapshot of the inputs, with the service's own controller.

        ``ctrl`` is the one taken when the request came (None: the current one).
        ``done`` gets (success, the CLI's JSON or the reason).
        """
        ctrl = self.controller if ctrl is None else ctrl
        start = time.perf_counter()
        try:
            self._solve(inputs, now, done, ctrl)
        finally:
            took = time.perf_counter() - start
            # The next queued solve waits: the loop keeps its share of the time.
            self._stopping.wait(took * (1.0 / WORKER_SHARE - 1.0))

    def _solve(self, inputs: Any, now: float, done: Future, ctrl: TorqueController) -> None:
        """Solve once and set ``done`` (:meth:`solve`)."""
        try:
            stale = ctrl.stale(now, inputs)
            if stale:
                done.set_result((False, f'cannot solve: {stale}'))
                return
            sol, maps, g = ctrl.solve_inputs(inputs, time.perf_counter() + ctrl.budget())
            cmd, _ = ctrl.gate(sol, g)
            if sol.status == 'infeasible':  # what can be held, and what binds (docs/planner.md)
                from grasp_torque_opt.methods.explain import explain

                sol.infeasibility = explain(ctrl.grasp_at(inputs)[0], maps).as_dict()
            d = solution_dict(sol, maps)
            d['command'] = None if cmd is None else [float(x) for x in cmd]
            d['gravity_torque'] = None if g is None else [float(x) for x in g]
            done.set_result((cmd is not None, strict_json(d)))
        except Exception as e:  # noqa: BLE001 -- the caller gets the reason, the node lives on
            done.set_result((False, f'cannot solve: {type(e).__name__}: {e}'))
