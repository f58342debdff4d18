# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Why infeasible when not even zero load holds: the infeasibility certificate names the cause."""

import box_grasp
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.methods.explain import explain
import pytest


def box(tmp_path, **kw):
    doc = box_grasp.scenario(**kw.pop('doc', {}))
    for key, value in kw.items():
        section, name = key.split('__')
        doc[section][name] = value
    return GraspSetup.from_file(box_grasp.write(tmp_path, doc))


def test_the_thumb_off_the_fingers_line_is_a_friction_conflict(tmp_path):
    setup = box(tmp_path)
    assert solve(setup).status == 'infeasible'
    why = explain(setup)
    c = why.capacity
    assert c.status == 'infeasible' and why.holdable_fraction == 0.0
    assert c.conflict.certified
    assert c.binding.joints == []  # 1000 N limits never bind
    kinds = {k for _, k in c.binding.contacts}
    assert kinds == {'friction cone', 'min normal force'}
    assert {link for link, k in c.binding.contacts if k == 'friction cone'} >= {'thumb_tip'}
    assert c.conflict.relaxed == {'torque_limits': False, 'friction': True,
                                  'min_normal_force': True}
    assert 'friction cones of' in why.text and 'thumb_tip' in why.text
    assert 'not holdable even with unlimited torques' in why.text
    d = why.as_dict()
    assert d['binding']['contacts'] and d['certified'] is True
    assert d['relaxed']['friction'] is True


def test_more_friction_holds_the_same_grasp(tmp_path):
    assert solve(box(tmp_path, doc={'mu': 1.0})).status == 'optimal'


def test_torque_limits_below_the_squeeze_are_named(tmp_path):
    # mu 1.0 takes friction out; 0.5 N limits cannot make the 1 N minimum normal force.
    setup = box(tmp_path, doc={'mu': 1.0}, hand__torque_limits=0.5)
    why = explain(setup)
    c = why.capacity
    assert c.status == 'infeasible' and c.conflict.certified
    assert c.binding.joints, why.text
    assert all(j.endswith('_x_joint') for j, _ in c.binding.joints)
    assert c.conflict.relaxed['torque_limits'] is True
    assert c.conflict.relaxed['friction'] is False
    assert 'torque limits of' in why.text


@pytest.mark.parametrize('flip', sorted(box_grasp.TIPS))
def test_a_flipped_box_normal_is_refused(tmp_path, flip):
    from grasp_torque_opt.core.exceptions import InputError

    with pytest.raises(InputError, match=r'^grasp\.contacts\[\d\]\.normal: .*'
                       + flip):
        GraspSetup.from_file(box_grasp.write(tmp_path, box_grasp.scenario(flip=flip)))
