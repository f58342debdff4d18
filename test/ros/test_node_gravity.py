# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The node's g(q) uses the scenario's gravity unless the ``gravity`` parameter says otherwise."""

import dataclasses
from pathlib import Path

from conftest import ALLEGRO, ALLEGRO_URDF, PLANAR
from cycle_inputs import joint_state
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import resolve_urdf
from grasp_torque_opt.methods.dispatch import solve
import numpy as np
import pinocchio as pin
from ros_harness import Harness


def test_gravity_defaults_to_the_scenarios_and_drives_g_of_q(allegro):
    h = Harness(ALLEGRO, gravity_compensation=True)
    try:
        assert list(h.node.get_parameter('gravity').value) == [9.81, 0.0, 0.0]
        q = allegro.q.copy()
        h.send_joint_state(*joint_state(allegro, q))
        cmd = h.next_command()
        model = pin.buildModelFromUrdf(str(resolve_urdf(ALLEGRO_URDF, Path('.'))))
        model.gravity.linear = np.array([9.81, 0.0, 0.0])  # the bundled file's, palm down
        g = pin.computeGeneralizedGravity(model, model.createData(), q)[allegro.hand.idx_v]
        ref = solve(dataclasses.replace(GraspSetup.from_file(ALLEGRO), torque_offset=g))
        np.testing.assert_allclose(cmd, ref.tau + g, atol=1e-9)
    finally:
        h.close()


def test_the_parameter_overrides_and_a_scenario_without_gravity_keeps_the_old_default():
    h = Harness(ALLEGRO, gravity=[0.0, 0.0, -9.81])
    try:
        assert list(h.node.get_parameter('gravity').value) == [0.0, 0.0, -9.81]
    finally:
        h.close()
    h = Harness(PLANAR)
    try:
        assert list(h.node.get_parameter('gravity').value) == [0.0, 0.0, -9.81]
    finally:
        h.close()
