# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""A contact normal pointing out of the object is refused at load, never certified as a pull."""

import copy

import box_grasp
from conftest import ALLEGRO, PLANAR, setup_from_doc
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.inward import surface_inward_normal
from grasp_torque_opt.core.scenario import ObjectSpec
import numpy as np
import pytest


@pytest.mark.parametrize('path', [PLANAR, ALLEGRO])
def test_the_bundled_scenarios_still_load(path):
    GraspSetup.from_file(path)


@pytest.mark.parametrize('i', [0, 1])
def test_a_normal_away_from_the_object_origin_names_its_contact(planar_doc, i):
    doc = copy.deepcopy(planar_doc)
    doc['grasp']['contacts'][i]['normal'] = [-x for x in doc['grasp']['contacts'][i]['normal']]
    link = doc['grasp']['contacts'][i]['link']
    with pytest.raises(InputError, match=rf'^grasp\.contacts\[{i}\]\.normal: the normal of the '
                       rf"contact on '{link}' points away from grasp\.object_origin"):
        setup_from_doc(doc)


def test_a_normal_against_the_objects_surface_is_refused(tmp_path):
    # The thumb's normal still has a positive component towards the object origin, but
    # points out of the box's +x face it touches.
    doc = box_grasp.scenario()
    doc['grasp']['object_origin'] = [0.03, 0.0, 0.0]
    doc['object']['position'] = [0.0, 0.0, 0.0]
    box_grasp.write(tmp_path, doc)
    doc['grasp']['contacts'][2]['normal'] = [1.0, 0.0, 0.0]
    with pytest.raises(InputError, match=r'^grasp\.contacts\[2\]\.normal: the normal of the '
                       r"contact on 'thumb_tip' points out of the object's box surface"):
        GraspSetup.from_file(box_grasp.write(tmp_path, doc))


@pytest.mark.parametrize('shape,size,point,inward', [
    ('sphere', [0.04], [0.0, 0.0, 0.04], [0, 0, -1]),
    ('box', [0.04, 0.08, 0.08], [0.02, 0.01, 0.0], [-1, 0, 0]),
    ('box', [0.04, 0.08, 0.08], [0.0, -0.039, 0.01], [0, 1, 0]),
    ('cylinder', [0.02, 0.1], [0.0, 0.02, 0.0], [0, -1, 0]),
    ('cylinder', [0.02, 0.1], [0.0, 0.005, -0.05], [0, 0, 1]),
])
def test_the_surface_normal_of_each_shape(shape, size, point, inward):
    obj = ObjectSpec(shape, np.array(size), 0.1, np.zeros(3), np.zeros(3))
    np.testing.assert_allclose(surface_inward_normal(obj, np.array(point)), inward, atol=1e-12)


def test_the_surface_normal_follows_the_objects_pose():
    obj = ObjectSpec('box', np.array([0.04, 0.08, 0.08]), 0.1, np.array([1.0, 0.0, 0.0]),
                     np.array([0.0, 0.0, np.pi / 2]))  # its x axis along base y
    np.testing.assert_allclose(surface_inward_normal(obj, np.array([1.0, 0.02, 0.0])),
                               [0, -1, 0], atol=1e-12)
