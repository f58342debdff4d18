# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The node's planner parameters over ROS.

friction_margin and objective change the command, and ~/solve reports the usage, the
ratio, and why an infeasible load is infeasible.
"""

import dataclasses
import json
import os

from conftest import ALLEGRO
from grasp_torque_opt.methods.dispatch import solve
from independent import assert_holds
import numpy as np
from rclpy.parameter import Parameter
from ros_harness import Harness
from std_srvs.srv import Trigger

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'


def service(h):
    future = h.solve_client.call_async(Trigger.Request())
    assert h.spin_until(future.done, 10.0)
    return future.result()


def test_margin_and_minmax_parameters_over_ros(allegro):
    h = Harness(ALLEGRO)
    try:
        names, positions = list(allegro.hand.joints), allegro.q[allegro.hand.idx_q]
        ok = h.node.set_parameters([Parameter('joint_state_timeout', value=5.0),  # load-proof
                                    Parameter('friction_margin', value=0.25),
                                    Parameter('objective', value='min-max')])
        assert all(r.successful for r in ok)
        h.send_joint_state(names, positions)
        cmd = h.next_command(5.0)
        ref_setup = dataclasses.replace(allegro, objective='min-max', friction=dataclasses.replace(
            allegro.friction, margin=0.25))
        ref = solve(ref_setup)
        np.testing.assert_allclose(cmd, ref.tau, atol=1e-6)
        res = service(h)
        d = json.loads(res.message)
        assert res.success and d['objective'] == 'min-max' and d['friction_margin'] == 0.25
        assert d['friction_usage_max'] <= 1 / 1.25 + 1e-7
        reduced = dataclasses.replace(allegro, friction=dataclasses.replace(
            allegro.friction, mu1=0.5 / 1.25, mu2=0.005 / 1.25))
        assert_holds(reduced, allegro.maps(), np.array(d['tau']),
                     np.array([c['wrench'] for c in d['contacts']]))
        refused = h.node.set_parameters([Parameter('objective', value='fastest')])[0]
        assert not refused.successful and 'objective: must be one of' in refused.reason
        refused = h.node.set_parameters([Parameter('solver.method',
                                                   value='tau-qp-adaptive')])[0]
        assert not refused.successful and 'min-max needs solver.method tau-qp' in refused.reason
        # An infeasible load (limits a tenth of the bundled ones): the service says why.
        assert h.node.set_parameters([Parameter('torque_limits', value=[0.07] * 16)])[0]\
            .successful
        h.send_joint_state(names, positions)
        h.spin_for(0.05)
        res = service(h)
        assert res.message.startswith('{'), res.message
        d = json.loads(res.message)
        assert not res.success and d['status'] == 'infeasible'
        assert 0 < d['infeasibility']['holdable_fraction'] < 1
        assert '% of this load can be held' in d['infeasibility']['text']
    finally:
        h.close()
