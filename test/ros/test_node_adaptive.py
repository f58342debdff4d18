# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The node with solver.method tau-qp-adaptive: real rclpy, real topics, a real service call."""

import dataclasses
import json

from conftest import ALLEGRO
from cycle_inputs import joint_state
from grasp_torque_opt.methods.dispatch import solve
import numpy as np
from rclpy.parameter import Parameter
from ros_harness import Harness
from std_srvs.srv import Trigger


def test_the_adaptive_method_commands_the_exact_optimum_and_reports_its_bounds(allegro):
    # A moving hand, and the exact optima first (Clarabel), so no joint state goes stale.
    qs, exact = [], []
    q = allegro.q.copy()
    for k in range(5):
        q = q.copy()
        q[allegro.hand.idx_q] += 1e-3 * (k % 2 - 0.5)
        qs.append(q)
        exact.append(solve(dataclasses.replace(allegro, q=q), 'socp').torque_norm)
    polygon = solve(dataclasses.replace(allegro, q=q)).tau
    h = Harness(ALLEGRO, solver__method='tau-qp-adaptive')
    try:
        assert h.node.controller.config.method == 'tau-qp-adaptive'
        for q, e in zip(qs, exact):  # warm across cycles (solver.warm_start's default)
            h.send_joint_state(*joint_state(allegro, q))
            cmd = h.next_command(5.0)
            assert cmd is not None
            # W = I: the command's norm within the default gap (0.1%) of the exact optimum.
            assert e * (1 - 1e-8) <= np.linalg.norm(cmd) <= e * (1 + 1e-3)
        assert h.node.controller.refiner.warm_solves >= 4
        h.send_joint_state(*joint_state(allegro, q))
        assert h.next_command(5.0) is not None
        future = h.solve_client.call_async(Trigger.Request())
        assert h.spin_until(future.done, 5.0)
        assert future.result().success, future.result().message
        d = json.loads(future.result().message)
        assert d['method'] == 'tau-qp-adaptive' and d['status'] == 'optimal'
        b = d['bounds']
        assert b['converged'] and b['lower'] <= e * (1 + 1e-8) <= b['upper'] * (1 + 1e-8)
        # Back to the paper's polygon at run time; a method the node does not run is refused.
        assert h.node.set_parameters([Parameter('solver.method', value='tau-qp')])[0].successful
        h.send_joint_state(*joint_state(allegro, q))
        np.testing.assert_allclose(h.next_command(5.0), polygon, atol=1e-6)
        refused = h.node.set_parameters([Parameter('solver.method', value='socp')])[0]
        assert not refused.successful and 'solver.method: must be one of' in refused.reason
    finally:
        h.close()
