# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Shared fixtures: the bundled scenarios and small variations of them."""

from __future__ import annotations

import copy
from pathlib import Path

from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.scenario import parse_scenario
import pytest
import yaml

ROOT = Path(__file__).resolve().parent.parent
CONFIG = ROOT / 'config'
PLANAR = CONFIG / 'planar_two_finger.yaml'
ALLEGRO = CONFIG / 'allegro_right.yaml'
#: The Allegro right hand that example-robot-data ships.
ALLEGRO_URDF = 'example-robot-data:allegro_hand_description/urdf/allegro_right_hand.urdf'


def scenario_doc(path: Path) -> dict:
    """Load a bundled scenario as plain data, to vary in a test."""
    return yaml.safe_load(path.read_text())


def setup_from_doc(doc: dict, base: Path = CONFIG) -> GraspSetup:
    """Bind a scenario document whose relative paths are relative to ``base``."""
    return GraspSetup.from_scenario(parse_scenario(copy.deepcopy(doc), base))


@pytest.fixture(scope='session')
def planar_doc() -> dict:
    return scenario_doc(PLANAR)


@pytest.fixture(scope='session')
def allegro_doc() -> dict:
    return scenario_doc(ALLEGRO)


@pytest.fixture(scope='session')
def planar(planar_doc) -> GraspSetup:
    return setup_from_doc(planar_doc)


@pytest.fixture(scope='session')
def allegro(allegro_doc) -> GraspSetup:
    return setup_from_doc(allegro_doc)


def with_contacts(doc: dict, contacts: list[dict]) -> dict:
    """Return a copy of a scenario document with other contacts."""
    out = copy.deepcopy(doc)
    out['grasp']['contacts'] = contacts
    return out


@pytest.fixture(scope='session')
def hyperstatic(planar_doc) -> GraspSetup:
    """
    Return the planar hand with two contacts on finger 1 and one on finger 2.

    The two on finger 1 are on its distal link and its tip.
    """
    contacts = copy.deepcopy(planar_doc['grasp']['contacts'])
    contacts.insert(1, {'link': 'finger1_distal', 'position': [0.0, 0.03, 0.0]})
    return setup_from_doc(with_contacts(planar_doc, contacts))


def pytest_terminal_summary(terminalreporter):
    """Print the adversarial campaign's counts (test_campaign*.py), even without -s."""
    from campaign import COUNTS, ISSUE33

    if COUNTS['inputs']:
        terminalreporter.write_line(
            f"campaign: {COUNTS['inputs']} inputs tried, {COUNTS['commands']} commands "
            f"published, {COUNTS['broken']} invariants broken; {COUNTS['pulling']} pulling, "
            f"{COUNTS['chattering']} chattering, {COUNTS['late']} late commands"
            + (f"; {COUNTS['unseen']} forbidden from consistent lies no check can see"
               if 'unseen' in COUNTS else ''))
    for case, c in ISSUE33.items():
        refused = ', '.join(f'{k} {v}' for k, v in c['refused'].items()) or 'none'
        extra = ''.join(f'; {k} {c[k]}' for k in (
            'joint states answered, still IMU then chatter', 'set changes', 'recovery steps')
            if k in c)
        terminalreporter.write_line(
            f"issue 33: {case}: {c['inputs']} inputs, {c['published']} commands published, "
            f"{c['received']} received, "
            f"{c['forbidden']} forbidden {c['kinds'] or ''}"
            f"{'' if c['seen'] else ' (unseen: a consistent lie)'}, {c['weak']} under "
            f"f_min, {c['zero']} zero; refused: {refused}{extra}; last: {c['why'][:160]}")
