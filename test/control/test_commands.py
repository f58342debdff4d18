# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The command interfaces: the certified torque in each driver's units, refusals as faults.

Each conversion is checked against its formula written again here (q_hold + tau / K,
tau / (k_t gear), the hybrid JointState's fields), on the Allegro's own cycle, and the
refusals (a current over its limit, a servo's torque over the torque limits, a target
outside the joint's range) are faults of the cycle: nothing committed, the policy's
counters and reason say so.
"""

from cycle_inputs import fresh, joint_state
from grasp_torque_opt.control.commands.base import Command
from grasp_torque_opt.control.commands.registry import COMMAND_INTERFACES, make_interface
from grasp_torque_opt.control.diagnostics import report
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.parameters.generated import CycleConfig
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.methods.dispatch import solve
import numpy as np
import pytest

INTERFACES = {
    'effort': {},
    'position': {'position_stiffness': (0.8,)},
    'current': {'current_torque_constant': (0.35,), 'current_gear_ratio': (2.0,),
                'current_limit': (2.0,)},
    'hybrid': {'hybrid_kp': (1.5,), 'hybrid_kd': (0.01,)},
}


def cycled(setup, q=None, **config):
    """Make a controller of the interface, take one joint state at q and cycle it."""
    ctrl = fresh(setup, **config)
    ctrl.take('joint_states', JointStateReading(*joint_state(setup, q)), 0.0)
    return ctrl, ctrl.cycle(0.0)


def test_the_registry_is_the_parameters_choices():
    assert COMMAND_INTERFACES == ('effort', 'position', 'current', 'hybrid')
    assert CycleConfig().command_interface == 'effort'


@pytest.mark.parametrize('name', sorted(INTERFACES))
def test_each_interface_commands_the_certified_torque_in_its_units(allegro, name):
    ctrl, r = cycled(allegro, command_interface=name, **INTERFACES[name])
    assert r.kind == 'solution' and r.fault == '', r.fault
    tau = solve(allegro).tau  # independent of the cycle: the core's solve
    np.testing.assert_allclose(r.command, tau, atol=1e-9)
    out, m = r.output, allegro.hand.m
    q = allegro.q[allegro.hand.idx_q]
    assert out.interface == name and out.well_formed(m)
    np.testing.assert_allclose(out.torque, r.command, atol=0)
    if name == 'effort':
        np.testing.assert_array_equal(out.values, r.command)
    elif name == 'position':  # rad: q_hold (the measured q) + tau / K
        np.testing.assert_allclose(out.values, q + r.command / 0.8, atol=1e-12)
    elif name == 'current':  # A: tau / (k_t gear)
        np.testing.assert_allclose(out.values, r.command / (0.35 * 2.0), atol=1e-12)
    else:  # JointState: position q_hold, velocity 0, effort tau
        np.testing.assert_allclose(out.position, q, atol=1e-12)
        np.testing.assert_array_equal(out.velocity, np.zeros(m))
        np.testing.assert_array_equal(out.values, r.command)


@pytest.mark.parametrize('name', ['position', 'hybrid'])
def test_q_hold_is_the_first_commands_measured_position_then_kept(allegro, name):
    ctrl, first = cycled(allegro, command_interface=name, **INTERFACES[name])
    q0 = allegro.q[allegro.hand.idx_q]
    moved = allegro.q.copy()
    moved[allegro.hand.idx_q] += 0.01  # every finger joint 10 mrad on
    ctrl.take('joint_states', JointStateReading(*joint_state(allegro, moved)), 0.01)
    second = ctrl.cycle(0.01)
    assert second.kind == 'solution', second.fault
    held = second.output.values - second.command / 0.8 if name == 'position' \
        else second.output.position
    np.testing.assert_allclose(held, q0, atol=1e-12)  # not the new measured position
    zero = ctrl.policy.interface.zero()
    np.testing.assert_allclose(zero.position if name == 'hybrid' else zero.values, q0)
    np.testing.assert_array_equal(zero.torque, np.zeros(allegro.hand.m))
    # /diagnostics says the interface and the reference held.
    d = dict(report(ctrl, 0.01).values)
    assert d['command_interface'] == name
    np.testing.assert_allclose([float(x) for x in d['command_interface.q_hold'].split(',')],
                               q0, rtol=1e-4)


def test_the_diagnostics_name_the_interface_and_a_reference_not_yet_taken(allegro):
    ctrl = fresh(allegro, command_interface='position', **INTERFACES['position'])
    d = dict(report(ctrl, 0.0).values)
    assert d['command_interface'] == 'position'
    assert d['command_interface.q_hold'] == 'not taken (no certified command yet)'
    d = dict(report(fresh(allegro), 0.0).values)
    assert d['command_interface'] == 'effort' and 'command_interface.q_hold' not in d


def test_a_current_over_its_limit_is_a_fault_not_a_clip(allegro):
    tau = solve(allegro).tau
    k = int(np.argmax(np.abs(tau)))
    limit = 0.5 * abs(tau[k]) / 0.35  # half the current the largest torque needs
    ctrl, r = cycled(allegro, command_interface='current', current_torque_constant=(0.35,),
                     current_limit=(limit,))
    assert r.kind == 'none' and r.command is None and r.output is None
    assert r.fault.startswith('current: ') and allegro.hand.joints[k] in r.fault, r.fault
    assert 'over current.limit' in r.fault
    assert ctrl.counters.faults == 1 and ctrl.counters.commands == 0
    assert ctrl.last_command is None  # nothing in force


def test_a_servo_torque_over_the_limits_is_a_fault(allegro):
    # Stiff servo, the fingers 0.2 rad off q_hold: K (q_hold - q) passes the 0.7 N m limit.
    ctrl, first = cycled(allegro, command_interface='position', position_stiffness=(5.0,))
    assert first.kind == 'solution'
    moved = allegro.q.copy()
    moved[allegro.hand.idx_q] -= 0.2
    ctrl.take('joint_states', JointStateReading(*joint_state(allegro, moved)), 0.01)
    r = ctrl.cycle(0.01)
    assert r.kind == 'none' and r.fault.startswith('position: the driver would produce'), \
        r.fault
    assert ctrl.counters.commands == 1 and ctrl.counters.faults == 1


def test_a_position_target_outside_the_joint_range_is_a_fault(allegro):
    # A soft servo: tau / K is radians beyond the joint's URDF range.
    ctrl, r = cycled(allegro, command_interface='position', position_stiffness=(1e-3,))
    assert r.kind == 'none' and 'outside its position limits' in r.fault, r.fault


@pytest.mark.parametrize('config, match', [
    ({'command_interface': 'position'}, 'position.stiffness.*must be set'),
    ({'command_interface': 'current', 'current_torque_constant': (0.35,)},
     'current.limit.*must be set'),
    ({'command_interface': 'hybrid', 'hybrid_kp': (1.0,)}, 'hybrid.kd.*must be set'),
    ({'command_interface': 'position', 'position_stiffness': (1.0, 2.0)},
     'position.stiffness.*1 entry or one per joint'),
    ({'command_interface': 'torque'}, 'command_interface.*must be one of effort, position'),
])
def test_an_interface_without_its_constants_is_refused_by_name(allegro, config, match):
    with pytest.raises(InputError, match=match):
        make_interface(CycleConfig(**config), allegro.hand)
    with pytest.raises(InputError, match=match):
        fresh(allegro, **config)


def test_well_formed_checks_every_array_but_the_one_the_caller_checked():
    good, bad = np.ones(3), np.array([1.0, np.nan, 1.0])
    assert Command('effort', good, good).well_formed(3, good)
    assert not Command('effort', good, bad).well_formed(3, good)  # the torque still checked
    assert not Command('hybrid', good, good, bad, np.zeros(3)).well_formed(3, good)
    assert not Command('hybrid', good, good, good, np.zeros(2)).well_formed(3, good)
    assert not Command('effort', bad, bad).well_formed(3)
    assert Command('effort', bad, bad).well_formed(3, bad)  # the caller's word is taken
