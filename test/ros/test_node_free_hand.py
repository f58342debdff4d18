# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
``hold_object`` set at run time on the real node: g(q) alone on the command topic.

The grasp comes back when it is set back; no contact arrows while the hand holds nothing.
"""

from pathlib import Path

from conftest import ALLEGRO, ALLEGRO_URDF
from cycle_inputs import joint_state
from grasp_torque_opt.core.hand import resolve_urdf
import numpy as np
import pinocchio as pin
from rclpy.parameter import Parameter
from ros_harness import Harness


def test_the_node_lets_go_and_grasps_again_at_run_time(allegro):
    h = Harness(ALLEGRO, gravity_compensation=True)
    try:
        q = allegro.q
        names, pos = joint_state(allegro, q)
        h.send_joint_state(names, pos)
        grasp = h.next_command()
        assert grasp is not None
        model = pin.buildModelFromUrdf(str(resolve_urdf(ALLEGRO_URDF, Path('.'))))
        model.gravity.linear = np.array([9.81, 0.0, 0.0])  # the scenario's, palm down
        g = pin.computeGeneralizedGravity(model, model.createData(), q)[allegro.hand.idx_v]
        (result,) = h.node.set_parameters([Parameter('hold_object', value=False)])
        assert result.successful, result.reason
        h.send_joint_state(names, pos)
        np.testing.assert_allclose(h.next_command(), g, atol=1e-9)
        h.markers.clear()
        h.spin_until(lambda: h.markers, 2.0)
        assert h.markers and all(m.action == m.DELETEALL for m in h.markers[-1].markers)
        (result,) = h.node.set_parameters([Parameter('hold_object', value=True)])
        assert result.successful, result.reason
        h.send_joint_state(names, pos)
        np.testing.assert_allclose(h.next_command(), grasp, atol=1e-7)
    finally:
        h.close()
