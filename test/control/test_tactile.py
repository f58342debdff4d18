# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The tactile input without ROS: its checks, and the measured usage and contact loss.

The usage and the loss are checked against an independent computation: the certified
contact forces turned into base axes, their tangential part taken off the normal there,
and (for the wrench form) the force expressed in the link's axes from a Pinocchio
placement of a model of the test's own.
"""

import dataclasses
from pathlib import Path

from conftest import ALLEGRO_URDF
from cycle_inputs import fresh, joint_state
from grasp_torque_opt.control.diagnostics import report
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.inputs.tactile import TactileArrayReading, \
    TactileWrenchReading
from grasp_torque_opt.control.tactile import measured_usage
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.hand import resolve_urdf
import numpy as np
import pinocchio as pin
import pytest

#: The Allegro V5 Sense's 16 entries: palm, thumb (3), index, middle, ring (4 each), the
#: fingertips last of each finger; the bundled scenario's link names.
V5_LINKS = ('', '', '', 'link_15.0_tip', '', '', '', 'link_3.0_tip', '', '', '',
            'link_7.0_tip', '', '', '', 'link_11.0_tip')
V5_TIPS = {'link_15.0_tip': 3, 'link_3.0_tip': 7, 'link_7.0_tip': 11, 'link_11.0_tip': 15}


def array_controller(allegro, **config):
    ctrl = fresh(allegro, tactile_source='array', tactile_links=V5_LINKS, **config)
    ctrl.take('joint_states', JointStateReading(*joint_state(allegro)), 1.0)
    return ctrl


def v5_array(normals: dict, palm: float = 0.0) -> np.ndarray:
    data = np.zeros(16)
    data[0] = palm
    for link, value in normals.items():
        data[V5_TIPS[link]] = value
    return data


def independent(result, mu1, measured):
    """Usage and loss from base-axis forces: f - (f.n) n over mu1 m, by hand."""
    usage, lost = [], []
    for i, frame in enumerate(result.maps.contacts):
        force = frame.rotation @ result.solution.wrenches[i, :3]
        n = frame.rotation[:, 2]
        tangential = np.linalg.norm(force - (force @ n) * n)
        usage.append(tangential / (mu1 * measured[i]))
        if measured[i] < 0.3 * (force @ n):
            lost.append(i)
    return np.array(usage), tuple(lost)


def test_measured_usage_and_loss_against_base_axis_forces(allegro):
    ctrl = array_controller(allegro)
    first = ctrl.cycle(1.0)
    assert first.kind == 'solution' and ctrl.tactile is not None
    assert ctrl.tactile.stale == (0, 1, 2, 3) and np.isnan(ctrl.tactile.usage).all()
    links = first.maps.links
    measured = np.array([1.2, 0.05, 0.9, 2.0])  # the middle finger's tip barely touching
    ctrl.take('tactile', TactileArrayReading(v5_array(dict(zip(links, measured)))), 1.01)
    result = ctrl.cycle(1.02)
    rep = ctrl.tactile
    usage, lost = independent(result, allegro.friction.mu1, measured)
    np.testing.assert_allclose(rep.measured, measured)
    np.testing.assert_allclose(rep.usage, usage, rtol=1e-9)
    assert rep.lost == lost == (1,) and rep.stale == ()
    d = dict(report(ctrl, 1.03).values)
    assert d['tactile.lost'].startswith('link_7.0_tip (0.050 N of')
    assert float(d['contact1.link_7.0_tip.measured_friction_usage']) == pytest.approx(
        usage[1], rel=1e-3)
    assert report(ctrl, 1.03).level == 1  # WARN: a contact lost, commands go on


def test_the_usage_function_edges():
    u = measured_usage(np.array([0.0, 0.3, 0.3, 0.3]), np.array([0.0, 0.0, np.nan, 0.6]), 0.5)
    assert u[0] == 0.0 and u[1] == np.inf and np.isnan(u[2]) and u[3] == pytest.approx(1.0)


def test_the_wrench_form_projects_on_the_planned_normal(allegro):
    ctrl = fresh(allegro, tactile_source='wrench')
    ctrl.take('joint_states', JointStateReading(*joint_state(allegro)), 1.0)
    result = ctrl.cycle(1.0)
    # Each link's planned force, in its own axes from a model of the test's own: the
    # measured normal force is then the planned one, the usage the planned tangential usage.
    model = pin.buildModelFromUrdf(str(resolve_urdf(ALLEGRO_URDF, Path('.'))))
    assert allegro.hand.base_link is None  # the base frame is the URDF's root
    data = model.createData()
    pin.framesForwardKinematics(model, data, allegro.q)
    for i, frame in enumerate(result.maps.contacts):
        force = frame.rotation @ result.solution.wrenches[i, :3]
        R = data.oMf[model.getFrameId(frame.link)].rotation
        ctrl.take('tactile_wrench', TactileWrenchReading(frame.link, R.T @ force, [0.0] * 3),
                  1.01)
    ctrl.cycle(1.02)
    rep = ctrl.tactile
    w = result.solution.wrenches
    np.testing.assert_allclose(rep.measured, w[:, 2], atol=1e-9)
    np.testing.assert_allclose(rep.usage, np.hypot(w[:, 0], w[:, 1])
                               / (allegro.friction.mu1 * w[:, 2]), rtol=1e-7)
    assert rep.lost == () and rep.stale == ()


@pytest.mark.parametrize('data, field, why', [
    (v5_array({'link_3.0_tip': float('nan')}), 'tactile.data[7]', 'not finite'),
    (v5_array({'link_3.0_tip': float('inf')}), 'tactile.data[7]', 'not finite'),
    (np.zeros(15), 'tactile.data', 'has 15 entries, tactile.links maps 16'),
    (np.zeros(17), 'tactile.data', 'has 17 entries'),
    (v5_array({'link_7.0_tip': -0.2}), 'tactile.data[11]', 'a sensor cannot pull'),
    (v5_array({}, palm=80.0), 'tactile.data[0]', 'above tactile.max_force'),
])
def test_a_bad_array_is_rejected_named_and_changes_nothing(allegro, data, field, why):
    ctrl = array_controller(allegro)
    ctrl.take('tactile', TactileArrayReading(v5_array({'link_3.0_tip': 1.0})), 1.0)
    kept = ctrl.inputs
    with pytest.raises(InputError, match=why) as e:
        ctrl.take('tactile', TactileArrayReading(data), 1.01)
    assert e.value.field == field and field in ctrl.last_rejection
    assert ctrl.inputs is kept and ctrl.counters.rejected['tactile'] == 1


def test_a_small_negative_reads_zero_and_an_unknown_link_is_refused(allegro):
    ctrl = array_controller(allegro)
    ctrl.take('tactile', TactileArrayReading(v5_array({'link_3.0_tip': -0.04})), 1.0)
    assert ctrl.inputs.tactile['link_3.0_tip'].normal == 0.0
    wrong = fresh(allegro, tactile_source='array',
                  tactile_links=V5_LINKS[:15] + ('link_11_tip',))
    with pytest.raises(InputError, match="tactile.links.15.: 'link_11_tip' is not a link"):
        wrong.take('tactile', TactileArrayReading(np.zeros(16)), 1.0)
    none = fresh(allegro, tactile_source='array', tactile_links=('',) * 16)
    with pytest.raises(InputError, match='tactile.links: maps no entry'):
        none.take('tactile', TactileArrayReading(np.zeros(16)), 1.0)


def test_a_bad_wrench_is_rejected_and_named(allegro):
    ctrl = fresh(allegro, tactile_source='wrench', tactile_links=('link_3.0_tip',))
    bad = [(('', [0.0, 0.0, 1.0]), 'frame_id: is empty'),
           (('no_link', [0.0, 0.0, 1.0]), "'no_link' is not a link of the hand"),
           (('link_7.0_tip', [0.0, 0.0, 1.0]), 'not in tactile.links (unmapped)'),
           (('link_3.0_tip', [float('nan'), 0.0, 1.0]), 'wrench.force: is not finite'),
           (('link_3.0_tip', [0.0, 0.0, 60.0]), 'above tactile.max_force')]
    for n, ((frame, force), why) in enumerate(bad, 1):
        with pytest.raises(InputError, match=why.replace('(', r'\(').replace(')', r'\)')):
            ctrl.take('tactile_wrench', TactileWrenchReading(frame, force, [0.0] * 3), 1.0)
        assert ctrl.counters.rejected['tactile_wrench'] == n and ctrl.inputs.tactile is None


def test_required_and_stale_is_a_fault_else_a_warning(allegro):
    required = array_controller(allegro, tactile_required=True, tactile_timeout=0.1)
    assert 'none received; tactile.required' in required.stale(1.0)
    assert required.cycle(1.0).kind == 'none'
    required.take('tactile', TactileArrayReading(v5_array(dict.fromkeys(V5_TIPS, 1.0))), 1.0)
    required.take('joint_states', JointStateReading(*joint_state(allegro)), 1.05)
    assert required.cycle(1.05).kind == 'solution'
    required.take('joint_states', JointStateReading(*joint_state(allegro)), 1.2)
    result = required.cycle(1.2)
    assert result.kind == 'none' and 'tactile stale (link_15.0_tip: 0.200 s' in result.fault
    # Not required (the default): commands go on, the report says stale.
    ctrl = array_controller(allegro, tactile_timeout=0.1)
    ctrl.take('tactile', TactileArrayReading(v5_array(dict.fromkeys(V5_TIPS, 1.0))), 1.0)
    ctrl.take('joint_states', JointStateReading(*joint_state(allegro)), 1.2)
    assert ctrl.cycle(1.2).kind == 'solution'
    assert ctrl.tactile.stale == (0, 1, 2, 3)
    rep = report(ctrl, 1.2)
    assert rep.level == 1 and 'tactile stale' in rep.message, rep.message


def test_no_source_no_report(allegro):
    ctrl = fresh(allegro)
    ctrl.take('joint_states', JointStateReading(*joint_state(allegro)), 1.0)
    assert ctrl.cycle(1.0).kind == 'solution' and ctrl.tactile is None
    assert dict(report(ctrl, 1.0).values)['tactile'] == 'off (tactile.source none)'
    assert dataclasses.fields(type(ctrl.config))  # a CycleConfig: tactile_source 'none'
    assert ctrl.config.tactile_source == 'none'


def test_the_squeeze_follows_the_touch_sensors_usage(allegro):
    ctrl = array_controller(allegro, object_loop=True, loop_squeeze=True, loop_rate=10.0,
                            loop_raise_at=0.8, loop_relax_at=0.5)
    base = allegro.friction.min_normal_force
    first = ctrl.cycle(1.0)
    links = first.maps.links
    squeeze = ctrl.solving.object_loop.squeeze
    # The sensors read every contact at a fifth of its planned normal force: the planned
    # tangential forces use the cone five times over (the slip evidence says nothing).
    planned = dict(zip(links, ctrl.tactile.planned))
    t = 1.0
    for _ in range(20):
        t += 0.004
        ctrl.take('tactile', TactileArrayReading(v5_array({k: 0.2 * v for k, v in
                                                           planned.items()})), t)
        ctrl.take('joint_states', JointStateReading(*joint_state(allegro)), t)
        ctrl.cycle(t)
    assert squeeze.source == 'tactile' and np.nanmax(squeeze.usage) > 1.0
    assert squeeze.normal_force > base
    raised = squeeze.normal_force
    # Without the squeeze the sensors' usage is reported, never used.
    plain = array_controller(allegro, object_loop=True)
    plain.cycle(1.0)
    plain.take('tactile', TactileArrayReading(v5_array({k: 0.2 * v for k, v in
                                                        planned.items()})), 1.004)
    plain.take('joint_states', JointStateReading(*joint_state(allegro)), 1.004)
    plain.cycle(1.004)
    assert plain.solving.object_loop.squeeze.normal_force is None
    # Stale sensors (no reading for longer than squeeze.usage_timeout): back to the slip
    # evidence, which sees none, and the squeeze relaxes.
    for _ in range(100):
        t += 0.02
        ctrl.take('joint_states', JointStateReading(*joint_state(allegro)), t)
        ctrl.cycle(t)
    assert squeeze.source == 'slip' and squeeze.normal_force < raised
