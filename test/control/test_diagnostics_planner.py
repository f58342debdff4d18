# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Diagnostics of the planner's numbers: friction usage on the unreduced cone with a margin."""

import dataclasses

from cycle_inputs import fresh, joint_state
from grasp_torque_opt.control.diagnostics import report
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
import numpy as np


def test_margined_usage_is_reported_on_the_unreduced_cone(allegro):
    setup = dataclasses.replace(allegro, friction=dataclasses.replace(allegro.friction,
                                                                      margin=0.5))
    ctrl = fresh(setup)
    ctrl.take('joint_states', JointStateReading(*joint_state(setup)), 0.0)
    r = ctrl.cycle(0.0)
    v = dict(report(ctrl, 0.0).values)
    fr = allegro.friction
    usages = []
    for i, (c, w) in enumerate(zip(allegro.contacts, r.solution.wrenches)):
        u = (np.hypot(w[0], w[1]) / fr.mu1 + abs(w[3]) / fr.mu2) / w[2]
        usages.append(u)
        assert float(v[f'contact{i}.{c.link}.friction_usage']) == float(f'{u:.4f}')
        assert u <= 1 / 1.5 + 1e-7
    assert float(v['friction_usage_max']) == float(f'{max(usages):.4f}')
    assert v['friction_margin'] == '0.5' and v['objective'] == 'sum-of-squares'
    lim = allegro.hand.torque_limits
    assert float(v['max_torque_ratio']) == float(f'{np.max(np.abs(r.solution.tau) / lim):.4f}')
