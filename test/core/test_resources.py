# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Bundled config files are found by name, from the source tree or an install."""

from conftest import CONFIG
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.resources import config_dirs, find_config
import pytest


@pytest.mark.parametrize('name', sorted(p.name for p in CONFIG.glob('*.yaml')))
def test_every_bundled_file_is_found_by_its_name(name):
    assert find_config(name).read_bytes() == (CONFIG / name).read_bytes()


def test_the_source_trees_config_is_a_candidate():
    assert CONFIG.resolve() in [d.resolve() for d in config_dirs()]


def test_a_missing_file_names_the_field_and_where_it_looked():
    with pytest.raises(InputError, match=r'params: file not found: nope\.yaml \(nor in .*config'):
        find_config('nope.yaml', 'params')
