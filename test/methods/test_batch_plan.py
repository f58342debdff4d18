# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The planner's own lines take the batch stages, and score there as on the single path.

Every line ``grasp-torque-opt plan`` writes carries ``object``, ``grasp.object_origin``
and ``grasp.contact_tolerance`` (docs/planner.md). :class:`BatchScorer` must take every
one of them (its ``single`` count stays 0) and give the single path's records. The load
(the object's weight about the line's origin) and the axis capacities (about that
origin) depend on each candidate's object: the records are checked against the single
path and against formulations written here: the equilibrium of the recorded wrenches
with the weight computed here on maps bound through the scenario file's route, and the
capacity LPs solved by SciPy's HiGHS (test/independent.py).
"""

import copy
from importlib import metadata
import json
import warnings

from conftest import ALLEGRO, scenario_doc, setup_from_doc
from grasp_torque_opt.backends.daqp import DAQP_C_VERSIONS
from grasp_torque_opt.control import compiled
from grasp_torque_opt.core.exceptions import GeometryWarning
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.methods.batch import BatchScorer
from grasp_torque_opt.methods.capacity import DIRECTIONS
from grasp_torque_opt.methods.plan import plan_grasps, PlanSettings
from grasp_torque_opt.methods.score import ScoreJob, Scorer
from grasp_torque_opt.native import loader
from independent import assert_holds, lp_capacity
import numpy as np
import pytest
from test_batch import assert_same

pytestmark = pytest.mark.skipif(not compiled.available(), reason=loader.IMPORT_ERROR)


@pytest.fixture(scope='module')
def planned() -> list[tuple[int, str]]:
    """Eight candidates of the bundled Allegro ball, as ``plan`` writes them, numbered."""
    plan = plan_grasps(ALLEGRO, PlanSettings(count=8, seed=0))
    assert len(plan.candidates) == 8
    return list(enumerate(plan.lines(), 1))


def bound(line: str):
    """Return (setup, maps, w_ext) of a line merged here into the bundled file's document."""
    data = json.loads(line)
    doc = copy.deepcopy(scenario_doc(ALLEGRO))
    doc['grasp'].update(data['grasp'])
    doc['load'] = data['load']
    origin = np.asarray(data['grasp']['object_origin'], dtype=float)
    w = np.asarray(data['load']['external_wrench'], dtype=float)
    if data['object'] is None:  # a mesh's line: the load is the whole load
        del doc['object'], doc['gravity']
    else:  # the weight about the line's origin, written out here
        doc['object'] = data['object']
        force = data['object']['mass'] * np.asarray(doc['gravity'], dtype=float)
        lever = np.asarray(data['object'].get('position', origin), dtype=float) - origin
        w = w + np.concatenate((force, np.cross(lever, force)))
    with warnings.catch_warnings():  # an object moved off the contacts is meant here
        warnings.simplefilter('ignore', GeometryWarning)
        setup = setup_from_doc(doc)
    return setup, setup.maps(), w


def test_every_line_of_plans_output_takes_the_batch_stages(planned):
    for _, line in planned:  # what the batch stages took to the single path before
        data = json.loads(line)
        assert 'object' in data and 'contact_tolerance' in data['grasp']
    job = ScoreJob.from_file(ALLEGRO, metrics='basic', solutions=True)
    batch = BatchScorer(Scorer(job))
    fast = batch.score_lines(planned)
    assert batch.single == 0 and batch.staged == len(planned)
    assert_same(fast, Scorer(job).score_lines(planned))
    for (_, line), rec in zip(planned, fast):
        assert rec['status'] == 'optimal'  # the planner keeps candidates that hold
        setup, maps, w = bound(line)
        tau, f = np.array(rec['tau']), np.array(rec['wrenches'])
        np.testing.assert_allclose(maps.G @ f.ravel() + w, 0.0, atol=1e-8)
        assert_holds(setup, maps, tau, f)


def moved(planned: list[tuple[int, str]]) -> list[tuple[int, str]]:
    """Return the plan's lines with the object off its origin, at its origin, or none."""
    out = []
    rng = np.random.default_rng(12)
    for n, line in planned:
        data = json.loads(line)
        kind = n % 3
        if kind == 0:  # the weight 1 cm off the origin: a moment
            data['object']['position'] = (np.asarray(data['object']['position'])
                                          + rng.uniform(-0.01, 0.01, 3)).tolist()
        elif kind == 1:  # no position: the object at the line's origin
            del data['object']['position']
        else:  # a mesh's line: no object, no gravity, the weight as the load
            data.update(object=None, gravity=None,
                        load={'external_wrench': [1.47, 0.0, 0.1, 0.0, 0.002, 0.0]})
        out.append((n, json.dumps(data)))
    return out


def test_full_metrics_of_plan_lines_match_the_single_path_and_highs(planned):
    lines = moved(planned)
    job = ScoreJob.from_file(ALLEGRO, metrics='full')
    batch = BatchScorer(Scorer(job))
    fast = batch.score_lines(lines)
    assert batch.single == 0 and batch.staged == len(lines)
    assert batch.capacity.redone == 0  # every LP answered by the batch's own DAQP calls
    assert_same(fast, Scorer(job).score_lines(lines), tol=1e-6)
    for (_, line), rec in zip(lines, fast):  # each kind: object moved, at its origin, none
        setup, maps, w = bound(line)
        np.testing.assert_allclose(setup.external_wrench, w, rtol=1e-12, atol=1e-15)
        alpha, _ = lp_capacity(setup, maps, w)
        assert rec['capacity'] == pytest.approx(alpha, rel=1e-6)
        for name, (i, sign) in DIRECTIONS.items():
            d = np.zeros(6)
            d[i] = sign
            value, _ = lp_capacity(setup, maps, d)
            assert rec['capacities'][name] == pytest.approx(value, rel=1e-6, abs=1e-9)


class Recorded:
    """The batch's compiled cycle, passed through, keeping each capacity_batch's arguments."""

    def __init__(self, cycle) -> None:
        self.cycle, self.calls = cycle, []

    def __getattr__(self, name: str):
        return getattr(self.cycle, name)

    def capacity_batch(self, *args):
        self.calls.append(args)
        return self.cycle.capacity_batch(*args)


def test_the_vertex_method_answers_the_compiled_lps_as_daqp_does(planned):
    # The compiled batch's LPs by the vertex method (the default) and, on the same
    # arguments, by DAQP alone (vertex=False): every LP answered by the vertex method
    # and passed, each alpha DAQP's to 1e-7.
    lines = moved(planned)
    job = ScoreJob.from_file(ALLEGRO, metrics='full')
    batch = BatchScorer(Scorer(job))
    if batch.capacity.entry is None:
        pytest.skip(f'daqp {metadata.version("daqp")} is not one of {DAQP_C_VERSIONS}')
    batch.capacity.cycle = recorded = Recorded(batch.capacity.cycle)
    batch.score_lines(lines)
    assert recorded.calls and batch.capacity.redone == 0
    for args in recorded.calls:
        by_vertex = recorded.cycle.capacity_batch(*args, vertex=True)
        by_daqp = recorded.cycle.capacity_batch(*args, vertex=False)
        assert by_vertex['vertex'].all() and by_vertex['passes'].all()
        assert by_daqp['passes'].all() and not by_daqp['vertex'].any()
        np.testing.assert_allclose(by_vertex['alpha'], by_daqp['alpha'],
                                   rtol=1e-7, atol=1e-12)
        # A load along an axis (the weight at the object's origin) is that axis's LP:
        # its answer taken (no pivots of its own), checked, and DAQP's alpha above.
        W, axes = args[4], args[5]
        direction = W / np.abs(W).max(axis=1, keepdims=True)
        along = (direction[:, None, :] == axes[None]).all(axis=2).any(axis=1)
        assert along.any() and not along.all()
        assert (by_vertex['iterations'][along, 1] == 0).all()
        assert (by_vertex['iterations'][~along, 1] > 0).all()


def test_fewer_contacts_take_the_vertex_method_at_their_own_size():
    # The vertex method is compiled for 7, 11 and 15 unknowns (3, 4, 5 contacts) and for
    # any size: two and three of the bundled grasp's contacts take the 3-unknown (any
    # size) and 7-unknown builds, every LP answered there and the single path's records.
    base = GraspSetup.from_file(ALLEGRO)
    picks = [[1, 3], [2, 3], [0, 1, 3], [0, 2, 3]]  # the thumb (3) against the fingers
    lines = [(k + 1, json.dumps({'grasp': {'contacts': [
        {'link': base.contacts[i].link, 'position': base.contacts[i].position.tolist()}
        for i in pick]}})) for k, pick in enumerate(picks)]
    job = ScoreJob.from_file(ALLEGRO, metrics='full')
    batch = BatchScorer(Scorer(job))
    if batch.capacity.entry is None:
        pytest.skip(f'daqp {metadata.version("daqp")} is not one of {DAQP_C_VERSIONS}')
    batch.capacity.cycle = recorded = Recorded(batch.capacity.cycle)
    fast = batch.score_lines(lines)
    assert batch.staged == len(lines) and batch.capacity.redone == 0
    assert_same(fast, Scorer(job).score_lines(lines), tol=1e-6)
    assert {args[2].shape[2] for args in recorded.calls} == {8, 12}  # 4 per contact
    for args in recorded.calls:
        out = recorded.cycle.capacity_batch(*args)
        assert out['vertex'].all() and out['passes'].all()
    assert all(rec['capacity_status'] == 'optimal' for rec in fast)


def test_the_compiled_lps_give_the_python_loops_answers(planned):
    # The 14 LPs per candidate solved in the compiled batch (the vertex method, DAQP's
    # C entry behind it) and from Python (one daqp.solve each): the same rows, the same
    # answers.
    lines = moved(planned)
    job = ScoreJob.from_file(ALLEGRO, metrics='full')
    compiled_lps, python_lps = BatchScorer(Scorer(job)), BatchScorer(Scorer(job))
    if metadata.version('daqp') in DAQP_C_VERSIONS:
        assert compiled_lps.capacity.entry is not None
    python_lps.capacity.entry = None
    fast, slow = compiled_lps.score_lines(lines), python_lps.score_lines(lines)
    assert compiled_lps.staged == python_lps.staged == len(lines)
    assert_same(fast, slow, tol=1e-12)


def test_contacts_found_from_geometry_take_the_single_path():
    # plan --contacts links: each line's contacts are found from geometry at its own
    # configuration and object (the single path), not read as points at the link origins.
    plan = plan_grasps(ALLEGRO, PlanSettings(count=3, seed=1, contacts='links'))
    lines = list(enumerate(plan.lines(), 1))
    assert all('position' not in c for _, line in lines
               for c in json.loads(line)['grasp']['contacts'])
    job = ScoreJob.from_file(ALLEGRO, metrics='basic')
    batch = BatchScorer(Scorer(job))
    assert_same(batch.score_lines(lines), Scorer(job).score_lines(lines))
    assert batch.single == len(lines) and batch.staged == 0


def test_a_grasp_that_cannot_hold_zero_load_has_capacity_zero_on_the_batch_path():
    # Two fingertips of the bundled grasp (index and middle) press the ball the same way:
    # their minimum normal forces push it, so zero load is not held, while a load
    # opposite their push is. The compiled LPs must not call zero load held (from an
    # axis's answer, or two opposite axes' combined): every capacity of such a
    # candidate is the single path's, 0 and infeasible.
    base = GraspSetup.from_file(ALLEGRO)
    maps = base.maps()
    two = [0, 1]
    push = maps.rotations[two, :, 2].sum(axis=0)  # inward normals: the object is pushed
    contacts = [{'link': base.contacts[i].link, 'position': base.contacts[i].position.tolist()}
                for i in two]
    lines = [(k + 1, json.dumps({'gravity': None, 'grasp': {'contacts': contacts}, 'load': {
        'external_wrench': [*(-scale * push), 0.0, 0.0, 0.0]}}))
        for k, scale in enumerate([0.6, 1.0, 1.5])]
    job = ScoreJob.from_file(ALLEGRO, metrics='full')
    batch = BatchScorer(Scorer(job))
    fast = batch.score_lines(lines)
    assert_same(fast, Scorer(job).score_lines(lines), tol=1e-6)
    assert batch.staged == len(lines)  # the tau-QP holds each load: the batch answered
    for rec in fast:
        assert (rec['capacity'], rec['capacity_status']) == (0.0, 'infeasible')
        assert set(rec['capacities'].values()) == {0.0}
