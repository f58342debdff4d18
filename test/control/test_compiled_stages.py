# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The compiled cycle's four stages, each held to its Python twin on the same inputs.

src/fast_cycle.hpp's ``run()`` is maps, build, solve_qp and certify in order; each is
exposed on ``FastCycle`` and compared here with the Python stage it was written from:
core/grasp_maps.py, core/tau_qp.build_tau_qp, backends/proxsuite.TauQPSolver (and
backends/daqp.DaqpSolver) and core/certificate.certify, on the bundled Allegro grasp and
perturbed joint states.
"""

import dataclasses
import os
import time

from grasp_torque_opt.backends import make_solver
from grasp_torque_opt.backends.proxsuite import TauQPSolver
from grasp_torque_opt.control import compiled
from grasp_torque_opt.core.certificate import certify
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.margin import planned_friction
from grasp_torque_opt.core.tau_qp import build_tau_qp
from grasp_torque_opt.native import loader
import numpy as np
import pytest

pytestmark = pytest.mark.skipif(
    bool(os.environ.get('GRASP_TORQUE_OPT_NO_COMPILED')),
    reason='GRASP_TORQUE_OPT_NO_COMPILED: built without the compiled cycle on purpose')

#: Relative agreement of two computations of the same array in double precision.
REL = 1e-12
#: ProxSuite's answers on the same QP: its own tolerance (eps_abs 1e-9), with room.
SOLVER_ATOL = 1e-7
RESIDUALS = ('equilibrium', 'torque', 'cone', 'normal_force', 'torque_limit')


def assert_near(got, ref, what, rel=REL):
    """Assert max |got - ref| <= rel * max(1, max |ref|), shapes equal."""
    got, ref = np.asarray(got, dtype=float), np.asarray(ref, dtype=float)
    assert got.shape == ref.shape, (what, got.shape, ref.shape)
    scale = max(1.0, float(np.abs(ref).max(initial=0.0)))
    err = float(np.abs(got - ref).max(initial=0.0))
    assert err <= rel * scale, f'{what}: {err:.3g} apart, more than {rel:g} x {scale:.3g}'


def states(setup, count=5, seed=11, scale=0.03):
    """Return the grasp at its own joint state, then at ``count - 1`` perturbed ones."""
    rng = np.random.default_rng(seed)
    out = [setup]
    for _ in range(count - 1):
        q = setup.q.copy()
        q[setup.hand.idx_q] += rng.normal(scale=scale, size=setup.hand.m)
        out.append(dataclasses.replace(setup, q=q))
    return out


def with_offset(setup, seed):
    """Return the grasp with a torque offset (as g(q) is) of a few hundredths of N m."""
    rng = np.random.default_rng(seed)
    return dataclasses.replace(setup, torque_offset=rng.normal(scale=0.03, size=setup.hand.m))


def cycle_for(setup, module=None):
    """Return a compiled cycle for the grasp, its ProxSuite warm-starting."""
    return compiled.CompiledCycle(setup, TauQPSolver(warm_start=True), 1e-6, module=module)


def compiled_maps(cycle, at, tree=False):
    """Run the compiled maps stage on Pinocchio's kinematics of ``at`` (or the tree's)."""
    c = cycle._arrays(at)
    if tree:
        oMf, J6 = (k[0] for k in cycle.tree.frames(np.array([at.q]), c.frame_ids))
    else:
        oMf, J6 = cycle.kinematics(at)
    return cycle._cycle.maps(oMf, J6, c.points, c.normals, c.has_normal, c.tangents,
                             c.has_tangent, at.object_origin)


def python_qp(at, maps=None):
    """Return the Python-built tau-QP of ``at`` (on its Python maps unless given)."""
    return build_tau_qp(at.maps() if maps is None else maps, planned_friction(at.friction),
                        at.external_wrench, *at.tau_bounds, at.weights)


def solve_stage(cycle, qp, **kw):
    """Run the compiled solve stage on a Python-built QP."""
    return cycle._cycle.solve_qp(qp.H, qp.g, qp.A, qp.b, qp.C, qp.u, qp.l_box, qp.u_box,
                                 qp.M1, qp.M2, qp.w, **kw)


@pytest.fixture(params=loader.MODULES)
def module(request):
    """Each build of the compiled cycle this CPU can load."""
    module, why = loader.load(request.param)
    assert module is not None, why
    return module


def test_maps_are_the_python_grasp_maps(allegro, module):
    cycle = cycle_for(allegro, module)
    for at in states(allegro):
        got = compiled_maps(cycle, at)
        ref = at.maps()
        for name in ('G', 'J', 'positions', 'rotations'):
            assert_near(got[name], getattr(ref, name), name)


def test_maps_with_given_normals_and_tangents(allegro, module):
    # Each contact's own normal and tangent (the contact-pose topic's way), not defaulted.
    rng = np.random.default_rng(4)
    base = allegro.maps()
    contacts = [dataclasses.replace(spec, normal=R[:, 2] + rng.normal(scale=0.05, size=3),
                                    tangent=R[:, 0] + rng.normal(scale=0.05, size=3))
                for spec, R in zip(allegro.contacts, base.rotations)]
    given = dataclasses.replace(allegro, contacts=contacts)
    cycle = cycle_for(given, module)
    for at in states(given, count=3):
        got, ref = compiled_maps(cycle, at), at.maps()
        for name in ('G', 'J', 'positions', 'rotations'):
            assert_near(got[name], getattr(ref, name), name)


def test_maps_refuse_what_the_python_maps_refuse(allegro):
    # A tangent along its normal: Python names the contact, the compiled stage hands back.
    contacts = list(allegro.contacts)
    contacts[2] = dataclasses.replace(contacts[2], normal=np.array([0.0, 0.0, 1.0]),
                                      tangent=np.array([0.0, 0.0, 2.0]))
    bad = dataclasses.replace(allegro, contacts=contacts)
    with pytest.raises(InputError, match=r'grasp\.contacts\[2\]'):
        bad.maps()
    with pytest.raises(ValueError, match='a contact frame cannot be made'):
        compiled_maps(cycle_for(bad), bad)


def test_build_is_the_python_tau_qp(allegro, module):
    cycle = cycle_for(allegro, module)
    for k, at in enumerate(states(allegro)):
        if k % 2:
            at = with_offset(at, k)
        maps = at.maps()
        ref = python_qp(at, maps)
        offset = np.zeros(0) if at.torque_offset is None else at.torque_offset
        got = cycle._cycle.build(maps.G, maps.J, at.external_wrench, offset)
        for name in ('H', 'g', 'C', 'u', 'l_box', 'u_box', 'M1', 'M2', 'w'):
            assert_near(got[name], getattr(ref, name), name)
        assert ref.N.shape[1] == 0  # the QR branch: no internal-force variables
        assert np.all(got['l'] == -np.inf) and got['l'].shape == ref.u.shape
        lo, hi = at.tau_bounds
        assert_near(got['tau_min'], lo, 'tau_min')
        assert_near(got['tau_max'], hi, 'tau_max')
        # A x = b is U_perp^T [w; tau] = 0 with U_perp a basis of A's left null space:
        # Eigen's QR and LAPACK's may give two bases, one turned in that space, so the
        # rows are compared through what a rotation leaves alone.
        A, b = got['A'], got['b']
        assert A.shape == ref.A.shape
        assert_near(A.T @ A, ref.A.T @ ref.A, 'A^T A')
        assert_near(A.T @ b, ref.A.T @ ref.b, 'A^T b')
        assert_near(b @ b, ref.b @ ref.b, 'b^T b')


def test_build_hands_back_a_rank_deficient_grasp(allegro):
    # Two contacts on one link: A = [G; J^T] loses column rank, the SVD branch's case.
    contacts = [allegro.contacts[0], dataclasses.replace(allegro.contacts[0])]
    two = dataclasses.replace(allegro, contacts=contacts)
    maps = two.maps()
    assert python_qp(two, maps).N.shape[1] > 0
    with pytest.raises(ValueError, match='not of full column rank'):
        cycle_for(two)._cycle.build(maps.G, maps.J, two.external_wrench, np.zeros(0))


def test_solve_is_the_python_proxsuite_solve(allegro, module):
    # The same QPs in the same order to both: cold first, then warm from the last answer.
    cycle, python = cycle_for(allegro, module), TauQPSolver(warm_start=True)
    for k, at in enumerate(states(allegro, count=8, scale=2e-3)):
        qp = python_qp(at)
        got, ref = solve_stage(cycle, qp), python.solve(qp)
        assert ref.status == 'solved' and got['solved'], (ref.message, got['message'])
        assert got['message'] == ref.message == 'PROXQP_SOLVED'
        assert_near(got['tau'], ref.x, 'tau', rel=SOLVER_ATOL)
        tau = got['tau']
        assert tau @ (qp.H @ tau) == pytest.approx(ref.x @ (qp.H @ ref.x), rel=SOLVER_ATOL)
        # f = M1 w + M2 tau, as TauQP.wrenches makes it from the same tau.
        assert_near(got['f'], qp.wrenches(tau), 'f')
        assert got['warm'] == python.last_warm == (k > 0)
    assert python.warm_solves == 7


def test_solve_is_the_python_daqp_solve(allegro, module):
    # DaqpSolver.solve's rules on the same QPs in the same order: cold first, then warm
    # (the compiled one from the last answer's active set, DaqpSolver from its workspace's).
    cycle = compiled.CompiledCycle(allegro, make_solver('daqp', warm_start=True), 1e-6,
                                   module=module)
    python = make_solver('daqp', warm_start=True)
    for k, at in enumerate(states(allegro, count=8, scale=2e-3)):
        qp = python_qp(at)
        got, ref = solve_stage(cycle, qp), python.solve(qp)
        assert ref.status == 'solved' and got['solved'], (ref.message, got['message'])
        assert got['message'] == ref.message == 'DAQP exit flag 1'
        assert_near(got['tau'], ref.x, 'tau', rel=SOLVER_ATOL)
        assert_near(got['f'], qp.wrenches(got['tau']), 'f')
        assert got['warm'] == python.last_warm == (k > 0)
        assert got['warm_solves'] == (k > 0) and got['redone_cold'] == 0
    # No time left: both stop before solving, with the same words.
    got = solve_stage(cycle, qp, time_left=0.0)
    ref = python.solve(qp, deadline=time.perf_counter())
    assert got['code'] == loader.fast_cycle.TIMED_OUT and ref.status == 'error'
    assert got['message'] == ref.message == 'time budget spent before DAQP started'


def test_solve_refuses_what_the_python_solver_refuses(allegro):
    cycle, python = cycle_for(allegro), TauQPSolver()
    qp = python_qp(allegro)
    cases = {'nan-data': dataclasses.replace(qp, C=qp.C * np.nan),
             'inverted-bounds': dataclasses.replace(qp, l_box=qp.u_box + 1.0)}
    for case, bad in cases.items():
        got, ref = solve_stage(cycle, bad), python.solve(bad)
        assert not got['solved'] and got['code'] == loader.fast_cycle.BAD_DATA, case
        assert ref.status == 'error' and got['message'] == ref.message, case
    # No time left: both stop before solving.
    got = solve_stage(cycle, qp, time_left=0.0)
    ref = python.solve(qp, deadline=time.perf_counter())
    assert got['code'] == loader.fast_cycle.TIMED_OUT and ref.status == 'error'
    assert got['message'].startswith('time budget spent')
    assert ref.message.startswith('time budget spent')


def certify_both(cycle, at, maps, tau, f):
    """Return the compiled and the Python certificate residuals of (tau, f)."""
    lo, hi = at.tau_bounds
    got = cycle._cycle.certify(maps.G, maps.J, at.external_wrench, lo, hi, tau, f)
    ref = certify(maps.G, maps.J, at.external_wrench, planned_friction(at.friction), lo, hi,
                  tau, f, 1e-6)
    return got, ref


def test_certify_is_the_python_certificate(allegro, module):
    cycle, python = cycle_for(allegro, module), TauQPSolver()
    rng = np.random.default_rng(2)
    violated = set()
    for k, at in enumerate(states(allegro)):
        at = with_offset(at, k)
        maps = at.maps()
        qp = python_qp(at, maps)
        x = python.solve(qp).x
        # The optimum, then (tau, f) moved off it: every residual away from zero.
        candidates = [(x, qp.wrenches(x))]
        for scale in (1e-3, 0.3):
            tau = x + rng.normal(scale=scale, size=x.size)
            f = qp.wrenches(x) + rng.normal(scale=scale, size=4 * maps.p)
            candidates.append((tau, f))
        for tau, f in candidates:
            got, ref = certify_both(cycle, at, maps, tau, f)
            for name, value in zip(RESIDUALS, got[:5]):
                assert_near(value, getattr(ref, name), name)
                if getattr(ref, name) > 1e-6:
                    violated.add(name)
            assert got[5] is ref.finite is True
    assert violated == set(RESIDUALS)  # each residual was compared where it bites


def test_certify_refuses_what_is_not_finite(allegro):
    cycle, maps = cycle_for(allegro), allegro.maps()
    tau, f = np.zeros(allegro.hand.m), np.zeros(4 * maps.p)
    f[5] = np.nan
    got, ref = certify_both(cycle, allegro, maps, tau, f)
    assert got == (np.inf,) * 5 + (False,) and not ref.finite
    assert all(getattr(ref, name) == np.inf for name in RESIDUALS)


def test_the_cycle_is_its_four_stages_in_order(allegro, module):
    # solve() on one compiled cycle, the four stages chained by hand on another, warm
    # starts included. Not to the last bit: the AVX2 build's sums over numpy's arrays
    # round by the arrays' alignment (1e-16 apart between two processes).
    whole, staged = cycle_for(allegro, module), cycle_for(allegro, module)
    for k, at in enumerate(states(allegro, count=6, scale=2e-3)):
        if k >= 3:
            at = with_offset(at, k)
        sol, maps = whole.solve(at, None)
        assert sol is not None, maps
        m = compiled_maps(staged, at, tree=True)  # as solve() computes them
        offset = np.zeros(0) if at.torque_offset is None else at.torque_offset
        qp = staged._cycle.build(m['G'], m['J'], at.external_wrench, offset)
        s = staged._cycle.solve_qp(qp['H'], qp['g'], qp['A'], qp['b'], qp['C'], qp['u'],
                                   qp['l_box'], qp['u_box'], qp['M1'], qp['M2'], qp['w'])
        cert = staged._cycle.certify(m['G'], m['J'], at.external_wrench, qp['tau_min'],
                                     qp['tau_max'], s['tau'], s['f'])
        for name in ('G', 'J', 'positions', 'rotations'):
            assert_near(getattr(maps, name), m[name], name)
        assert_near(sol.tau, s['tau'], 'tau')
        assert_near(sol.wrenches.reshape(-1), s['f'], 'f')
        assert whole.solver.last_warm == s['warm'] == (k > 0)
        for name, value in zip(RESIDUALS, cert[:5]):
            assert_near(getattr(sol.certificate, name), value, name)


def test_the_compiled_kinematics_are_pinocchios(allegro, module):
    # The same cycles with the contact links' kinematics computed in the compiled call
    # (the hand's tree) and asked of Pinocchio in Python: the same maps and answers.
    inside, outside = cycle_for(allegro, module), cycle_for(allegro, module)
    assert inside.tree is not None and inside._cycle.uses_tree
    outside.tree = None  # before its first contacts: Pinocchio's kinematics in Python
    for at in states(allegro, count=6, scale=0.2):
        (a, maps_a), (b, maps_b) = inside.solve(at, None), outside.solve(at, None)
        assert a is not None and b is not None, (maps_a, maps_b)
        for name in ('G', 'J', 'positions', 'rotations'):
            assert_near(getattr(maps_a, name), getattr(maps_b, name), name)
        assert_near(a.tau, b.tau, 'tau', rel=SOLVER_ATOL)
    assert inside._contacts.frames is not None and outside._contacts.frames is None


def test_the_compiled_kinematics_refuse_tables_that_do_not_fit(allegro):
    cycle = cycle_for(allegro)
    tables = cycle.tree.tables
    model = allegro.hand.model
    with pytest.raises(ValueError, match='wrong shape'):
        cycle._cycle.use_tree(*tables[:-1], tables[-1][:-1], model.nq, model.nv)
    with pytest.raises(ValueError, match='out of range'):
        cycle._cycle.use_tree(*tables, model.nq, 1)
    c = cycle._arrays(allegro)
    fparent, Rf, tf = c.frames
    at = allegro
    for q, parents in ((at.q[:-1], fparent), (at.q, fparent + model.njoints)):
        a = cycle._cycle.solve_q(q, parents, Rf, tf, c.points, c.normals, c.has_normal,
                                 c.tangents, c.has_tangent, at.object_origin,
                                 at.external_wrench, np.zeros(0), -1.0)
        assert a.code == loader.fast_cycle.NOT_HANDLED and 'wrong shape' in a.message


def test_the_bound_contacts_answer_as_the_arrays_given_each_call(allegro, module):
    # solve_bound holds what solve_q is given each call; the two compiled cycles, one fed
    # each way, give the same answers (to rounding: two objects' Eigen storage may be
    # aligned apart, and vector loops round in another order), and the parts are the
    # answer's attributes bit for bit.
    bound, given = cycle_for(allegro, module), cycle_for(allegro, module)
    a = bound._cycle.solve_bound(allegro.q, allegro.object_origin, allegro.external_wrench,
                                 np.zeros(0), -1.0)
    assert a.code == module.NOT_HANDLED and 'no contacts bound' in a.message
    c = given._arrays(allegro)
    bound._arrays(allegro)  # binds its contact list
    for at in states(allegro, count=4, scale=0.2):
        x = bound._cycle.solve_bound(at.q, at.object_origin, at.external_wrench, np.zeros(0),
                                     -1.0)
        y = given._cycle.solve_q(at.q, *c.frames, c.points, c.normals, c.has_normal,
                                 c.tangents, c.has_tangent, at.object_origin,
                                 at.external_wrench, np.zeros(0), -1.0)
        assert x.code == y.code == module.CERTIFIED, (x.message, y.message)
        tau, f, G, J, positions, rotations, usage, cert, timings = x.parts
        for name, got in (('tau', tau), ('f', f), ('G', G), ('J', J),
                          ('positions', positions), ('rotations', rotations),
                          ('usage', usage)):
            assert np.array_equal(got, getattr(x, name)), name
            assert_near(got, getattr(y, name), name)
        assert cert == x.certificate and timings == x.timings
