# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Why infeasible: the holdable fraction, and that what it names binds in an independent solve."""

import dataclasses

from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.methods.explain import explain
from independent import lp_capacity, polygon_slack
import numpy as np
import pytest


def named_are_active(setup):
    """
    Check that the explanation's fraction equals an independent HiGHS LP's.

    Every constraint it names must also be active at that LP's optimum.
    """
    maps = setup.maps()
    assert solve(setup, maps=maps).status == 'infeasible'
    why = explain(setup, maps)
    alpha, f = lp_capacity(setup, maps, setup.external_wrench)  # HiGHS, contact-force space
    assert 0 < alpha < 1
    assert why.holdable_fraction == pytest.approx(alpha, rel=1e-6)
    binding = why.capacity.binding
    assert binding.joints or binding.contacts
    tau = maps.J.T @ f
    lim = setup.hand.torque_limits
    joints = list(setup.hand.joints)
    for name, side in binding.joints:
        j = joints.index(name)
        assert tau[j] == pytest.approx(lim[j] if side == 'upper' else -lim[j], abs=1e-6), name
    wrenches = f.reshape(-1, 4)
    for link, kind in binding.contacts:
        i = list(maps.links).index(link)
        if kind == 'friction cone':
            assert abs(polygon_slack(setup, wrenches[i])) <= 1e-7, link
        else:
            assert wrenches[i, 2] == pytest.approx(setup.friction.min_normal_force, abs=1e-6)
    assert f'{100 * alpha:.1f}%' in why.text
    for name, _ in binding.joints:
        assert name in why.text


@pytest.mark.parametrize('load', [[14.715, 0, 0, 0, 0, 0], [0, 0, -12.0, 0, 0, 0],
                                  [-9.0, 0, 0, 0.0, 0.2, 0]])
def test_the_named_constraints_are_active_in_an_independent_solve(allegro, load):
    named_are_active(dataclasses.replace(allegro, external_wrench=np.array(load, float)))


def test_the_same_on_random_infeasible_grasps(allegro):
    from test_capacity import random_grasps

    for setup in random_grasps(allegro, 6, seed=21):
        named_are_active(dataclasses.replace(setup, external_wrench=25 * setup.external_wrench))


def test_a_holdable_load_is_explained_as_holdable(allegro):
    why = explain(allegro)
    assert why.holdable_fraction > 1 and 'disagree' in why.text
