# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The diagnostic report is a pure function of the controller's state."""

import dataclasses

from cycle_inputs import fresh, joint_state
from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.control.diagnostics import ERROR, OK, report, STALE, WARN
from grasp_torque_opt.control.inputs.external_wrench import WrenchReading
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.parameters.generated import CycleConfig
from grasp_torque_opt.core.exceptions import InputError
import numpy as np
import pytest


def values(rep):
    return dict(rep.values)


def test_levels_follow_the_cycle(planar):
    ctrl = fresh(planar, joint_state_timeout=0.05, hold_time=0.1, fault_policy='zero')
    rep = report(ctrl, 0.0)
    assert rep.level == STALE and rep.message == 'waiting for joint_states'
    ctrl.take('joint_states', JointStateReading(*joint_state(planar)), 0.0)
    ctrl.cycle(0.0)
    rep = report(ctrl, 0.01)
    v = values(rep)
    assert rep.level == OK and v['status'] == 'optimal' and v['certificate.ok'] == 'true'
    assert float(v['torque_norm']) > 0 and int(v['iterations']) > 0
    for i, c in enumerate(planar.contacts):
        usage = float(v[f'contact{i}.{c.link}.tangential_usage'])
        assert 0.0 <= usage <= 1.0 + 1e-6
        assert float(v[f'contact{i}.{c.link}.torsional_usage']) <= 1.0 + 1e-6
    ctrl.watchdog(0.08)
    rep = report(ctrl, 0.08)
    assert rep.level == WARN and rep.message.startswith('holding last certified command')
    ctrl.watchdog(0.2)
    rep = report(ctrl, 0.2)
    assert rep.level == ERROR and rep.message.startswith('zero torques published')
    assert values(rep)['zero_commands'] == '1' and values(rep)['faults'] == '1'


def test_rejections_are_reported(planar):
    ctrl = fresh(planar)
    with pytest.raises(InputError):
        ctrl.take('joint_states', JointStateReading(['joint1'], [0.0, 1.0]), 0.0)
    v = values(report(ctrl, 0.0))
    assert v['rejected.joint_states'] == '1'
    assert v['last_rejection'] == 'joint_states: 1 names but 2 positions'


def test_friction_usage_matches_the_wrenches(allegro):
    ctrl = fresh(allegro)
    ctrl.take('joint_states', JointStateReading(*joint_state(allegro)), 0.0)
    r = ctrl.cycle(0.0)
    v = values(report(ctrl, 0.0))
    mu1 = allegro.friction.mu1
    for i, (c, w) in enumerate(zip(allegro.contacts, r.solution.wrenches)):
        expected = np.hypot(w[0], w[1]) / (mu1 * w[2])
        assert float(v[f'contact{i}.{c.link}.tangential_usage']) == \
            float(f'{expected:.4f}')


def test_warm_starts_and_their_fallbacks_are_reported(allegro):
    ctrl = TorqueController(dataclasses.replace(allegro, hand=dataclasses.replace(allegro.hand)),
                            CycleConfig(cycle_budget=10.0), backend='daqp', warm_start=True)
    names, positions = joint_state(allegro)
    ctrl.take('joint_states', JointStateReading(names, positions), 0.0)
    assert ctrl.cycle(0.0).kind == 'solution'
    ctrl.take('joint_states', JointStateReading(names, positions), 0.01)
    assert ctrl.cycle(0.01).kind == 'solution'
    # A load no grasp holds: the warm answer is not optimal, so it is redone cold.
    ctrl.take('external_wrench',
              WrenchReading('', allegro.external_wrench[:3] * 100, np.zeros(3)), 0.02)
    ctrl.take('joint_states', JointStateReading(names, positions), 0.02)
    assert ctrl.cycle(0.02).kind == 'none'
    v = values(report(ctrl, 0.02))
    assert v['solver.backend'] == 'daqp'
    assert v['solver.warm_solves'] == '2' and v['solver.warm_start_fallbacks'] == '1'


def test_fallback_solves_are_reported(allegro):
    """A first backend whose answers fail the certificate: DAQP's are published, and counted."""
    ctrl = TorqueController(dataclasses.replace(allegro, hand=dataclasses.replace(allegro.hand)),
                            CycleConfig(cycle_budget=10.0), fallback='daqp')
    good = ctrl.solver

    class Wrong:
        name, settings = 'wrong', good.settings

        def solve(self, qp):
            r = good.solve(qp)
            return dataclasses.replace(r, x=r.x + 0.05)

    ctrl.solver = Wrong()
    names, positions = joint_state(allegro)
    ctrl.take('joint_states', JointStateReading(names, positions), 0.0)
    result = ctrl.cycle(0.0)
    assert result.kind == 'solution' and result.solution.backend == 'daqp'
    assert values(report(ctrl, 0.0))['solver.fallback_solves'] == '1'
