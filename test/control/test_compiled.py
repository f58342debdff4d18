# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The compiled cycle (src/fast_cycle.hpp) against the Python cycle and independent solvers.

The Python cycle is the reference; the optimum of each compiled command is checked
against another method (DAQP, a dual active-set method, for ProxSuite's; quadprog for
DAQP's) on the QP the Python builder makes, and its certificate against the Python
certificate of the same (tau, f).
"""

import dataclasses
import os

from conftest import setup_from_doc, with_contacts
from cycle_inputs import base_poses, fresh, joint_state
from grasp_torque_opt.backends import make_solver
from grasp_torque_opt.backends.proxsuite import TauQPSolver
from grasp_torque_opt.control import compiled
from grasp_torque_opt.control.diagnostics import report
from grasp_torque_opt.control.inputs.contacts import ContactsReading
from grasp_torque_opt.control.inputs.external_wrench import WrenchReading
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.core.certificate import certify
from grasp_torque_opt.core.margin import planned_friction
from grasp_torque_opt.core.tau_qp import build_tau_qp
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.native import loader
from independent import assert_holds
import numpy as np
import pinocchio as pin
import pytest

pytestmark = pytest.mark.skipif(
    bool(os.environ.get('GRASP_TORQUE_OPT_NO_COMPILED')),
    reason='GRASP_TORQUE_OPT_NO_COMPILED: built without the compiled cycle on purpose')


def moving_states(setup, count, seed=0, scale=2e-3):
    """Return joint positions drifting smoothly with random steps on top, shape (count, m)."""
    rng = np.random.default_rng(seed)
    q0 = setup.q[setup.hand.idx_q]
    t = np.arange(count)[:, None] * 1e-3
    smooth = scale * np.sin(2.0 * np.pi * t + 0.4 * np.arange(q0.size))
    return q0 + smooth + rng.normal(scale=scale / 4, size=smooth.shape)


def run(ctrl, setup, qs):
    """Feed joint states to a controller and return its results."""
    names = list(setup.hand.joints)
    out = []
    for i, q in enumerate(qs):
        now = 1.0 + 1e-3 * i
        ctrl.take('joint_states', JointStateReading(names, q.tolist()), now)
        out.append(ctrl.cycle(now))
    return out


def reference(setup, q, g, backend='daqp'):
    """Solve cold the Python-built QP at q, with the offset g (DAQP, or the backend named)."""
    full = setup.q.copy()
    full[setup.hand.idx_q] = q
    at = dataclasses.replace(setup, q=full, torque_offset=g)
    sol = solve(at, solver=make_solver(backend))
    assert sol.optimal, sol.message
    return sol, at


#: Each backend the compiled cycle solves with: its warm solver, the independent solver
#: its commands are held to (another method: DAQP's dual active set for ProxSuite's
#: augmented Lagrangian, Goldfarb-Idnani's quadprog for DAQP), and the message of a
#: certified answer.
BACKENDS = {'proxsuite': (lambda: TauQPSolver(warm_start=True), 'daqp',
                          'certified (solver: PROXQP_SOLVED)'),
            'daqp': (lambda: make_solver('daqp', warm_start=True), 'quadprog',
                     'certified (solver: DAQP exit flag 1)')}


def test_the_compiled_cycle_is_built():
    # The README's setup builds it; without it the node runs 3 to 4 times slower.
    assert compiled.available(), loader.IMPORT_ERROR
    for name in loader.MODULES:  # and the AVX2 build where this CPU runs it
        assert loader.load(name)[0] is not None, loader.load(name)[1]
    assert loader.fast_cycle.__name__.endswith(loader.MODULES[0])


@pytest.mark.parametrize('backend', BACKENDS)
@pytest.mark.parametrize('gravity', [False, True])
def test_commands_are_the_optimum_of_independent_solvers(allegro, gravity, backend):
    warm, independent, message = BACKENDS[backend]
    fast = fresh(allegro, gravity_compensation=gravity)
    fast.solver = warm()
    slow = fresh(allegro, gravity_compensation=gravity, compiled=False)
    slow.solver = warm()
    # No deadline for either: a stall of this process (a loaded machine) raises a solver's
    # measured time per iteration, and with it cuts the next solves' caps; the commands
    # compared here must not depend on the wall clock.
    fast.untimed = slow.untimed = True
    qs = moving_states(allegro, 300)
    got, ref = run(fast, allegro, qs), run(slow, allegro, qs)
    assert fast.compiled_cycle is not None and slow.compiled_cycle is None
    assert fast.compiled_cycle.solves == 300 and fast.compiled_cycle.handed_back == 0
    # Warm starts were taken (and counted on the solver, as the Python cycle counts them).
    assert fast.solver.warm_solves == 299
    for i in range(0, 300, 7):
        a, b = got[i], ref[i]
        assert a.kind == b.kind == 'solution', (i, a.fault, b.fault)
        np.testing.assert_allclose(a.command, b.command, atol=1e-6)
        other, at = reference(allegro, qs[i], a.gravity_torque, independent)
        np.testing.assert_allclose(a.solution.tau, other.tau, atol=1e-6)
        # The compiled certificate is the Python one of the same (tau, f).
        lo, hi = at.tau_bounds
        f = a.solution.wrenches.reshape(-1)
        py_maps = at.maps()
        cert = certify(py_maps.G, py_maps.J, at.external_wrench, planned_friction(at.friction),
                       lo, hi, a.solution.tau, f, a.solution.certificate.tolerance)
        for k in ('equilibrium', 'torque', 'cone', 'normal_force', 'torque_limit'):
            assert abs(getattr(cert, k) - getattr(a.solution.certificate, k)) <= 1e-12, k
        assert cert.ok and a.solution.certificate.ok
        # The maps it returns are Pinocchio's, as the Python builder makes them.
        np.testing.assert_allclose(a.maps.G, py_maps.G, atol=1e-12)
        np.testing.assert_allclose(a.maps.J, py_maps.J, atol=1e-12)
        np.testing.assert_allclose(a.maps.rotations, py_maps.rotations, atol=1e-12)
        np.testing.assert_allclose(a.maps.positions, py_maps.positions, atol=1e-12)
        # Independently of the package's builders: it holds the load.
        assert_holds(at, py_maps, a.solution.tau, a.solution.wrenches)
        # The planner's numbers, as the Python cycle gives them.
        np.testing.assert_allclose(a.solution.friction_usage, b.solution.friction_usage,
                                   atol=1e-6)
        assert abs(a.solution.max_torque_ratio - b.solution.max_torque_ratio) <= 1e-6
        assert a.solution.message == message
    values = dict(report(fast, 2.0).values)
    assert values['solver.compiled'] == 'true'
    assert values['solver.compiled_solves'] == '300'
    assert dict(report(slow, 2.0).values)['solver.compiled'] == 'false: off (compiled: false)'


def test_contact_poses_and_a_load_from_the_topics(allegro):
    fast, slow = fresh(allegro), fresh(allegro, compiled=False)
    pos, quat = base_poses(allegro)
    rng = np.random.default_rng(3)
    for k in range(20):
        # Contact points moved and frames turned a little about random axes.
        moved = pos + rng.normal(scale=1e-4, size=pos.shape)
        turned = np.array([(pin.Quaternion(pin.exp3(rng.normal(scale=0.02, size=3))) *
                            pin.Quaternion(np.asarray(x))).coeffs() for x in quat])
        force, torque = [0.0, 0.1 * rng.normal(), -1.0 - 0.05 * k], [0.0, 0.01, 0.0]
        results = []
        for ctrl in (fast, slow):
            now = 1.0 + 0.01 * k
            ctrl.take('joint_states', JointStateReading(*joint_state(allegro)), now)
            ctrl.take('contacts', ContactsReading('', moved, turned), now)
            ctrl.take('external_wrench', WrenchReading('', force, torque), now)
            results.append(ctrl.cycle(now))
        a, b = results
        assert a.kind == b.kind == 'solution', (a.fault, b.fault)
        np.testing.assert_allclose(a.command, b.command, atol=1e-6)
        np.testing.assert_allclose(a.maps.G, b.maps.G, atol=1e-12)
        np.testing.assert_allclose(a.maps.J, b.maps.J, atol=1e-12)
        np.testing.assert_allclose(a.maps.rotations, b.maps.rotations, atol=1e-12)
    assert fast.compiled_cycle.solves == 20 and fast.compiled_cycle.handed_back == 0


def test_an_infeasible_load_is_handed_back_and_confirmed_by_the_lp(allegro):
    heavy = dataclasses.replace(allegro, external_wrench=np.array([0, 0, -500.0, 0, 0, 0]))
    fast = fresh(heavy)
    fast.solver = TauQPSolver(warm_start=True)
    fast.fallback = make_solver('daqp')
    slow = fresh(heavy, compiled=False)
    slow.fallback = make_solver('daqp')
    names, pos = joint_state(heavy)
    for ctrl in (fast, slow):
        ctrl.take('joint_states', JointStateReading(names, pos), 1.0)
    a, b = fast.cycle(1.0), slow.cycle(1.0)
    assert a.kind != 'solution' and b.kind != 'solution'
    assert a.solution.status == b.solution.status == 'infeasible'
    assert 'after the compiled cycle: PROXQP' in a.solution.message
    assert fast.compiled_cycle.handed_back == 1 and fast.compiled_cycle.solves == 0
    # Then a holdable load again: the compiled cycle answers.
    for ctrl in (fast, slow):
        ctrl.setup = allegro
        ctrl.take('joint_states', JointStateReading(names, pos), 1.1)
    a, b = fast.cycle(1.1), slow.cycle(1.1)
    assert a.kind == b.kind == 'solution'
    np.testing.assert_allclose(a.command, b.command, atol=1e-6)
    assert fast.compiled_cycle.solves == 1


def test_no_time_left_is_a_timeout_and_bad_data_is_refused(allegro):
    cycle = compiled.CompiledCycle(allegro, TauQPSolver(warm_start=True), 1e-6)
    sol, why = cycle.solve(allegro, 0.0)
    assert sol is None and 'time budget spent' in why
    assert cycle.last_code in compiled.SOLVER_CODES and cycle.solver.timeouts == 1
    nan = dataclasses.replace(allegro, external_wrench=np.full(6, np.nan))
    sol, why = cycle.solve(nan, None)
    assert sol is None and why == 'compiled cycle: QP data not finite'
    assert cycle.last_code not in compiled.SOLVER_CODES  # the Python cycle answers it
    # And it still answers a good grasp after both.
    sol, maps = cycle.solve(allegro, None)
    assert sol.optimal and maps.G.shape == (6, 16)


def test_daqp_hands_back_no_time_left_and_an_infeasible_load(allegro):
    cycle = compiled.CompiledCycle(allegro, make_solver('daqp', warm_start=True), 1e-6)
    sol, why = cycle.solve(allegro, 0.0)
    assert sol is None and why == 'compiled cycle: time budget spent before DAQP started'
    assert cycle.last_code == loader.fast_cycle.TIMED_OUT
    sol, maps = cycle.solve(allegro, None)
    assert sol.optimal and sol.message == 'certified (solver: DAQP exit flag 1)'
    # Too heavy: DAQP says infeasible (exit flag -1), handed back to the fallback and LP.
    heavy = dataclasses.replace(allegro, external_wrench=np.array([0, 0, -500.0, 0, 0, 0]))
    sol, why = cycle.solve(heavy, None)
    assert sol is None and why == 'compiled cycle: DAQP exit flag -1'
    assert cycle.last_code in compiled.SOLVER_CODES
    fast = fresh(heavy)
    fast.solver = make_solver('daqp', warm_start=True)
    fast.fallback = make_solver('proxsuite')
    fast.take('joint_states', JointStateReading(*joint_state(heavy)), 1.0)
    a = fast.cycle(1.0)
    assert a.kind != 'solution' and a.solution.status == 'infeasible'
    assert 'after the compiled cycle: DAQP exit flag -1' in a.solution.message
    # A warm start from the heavy load's last solved active set (the good grasp's, as the
    # heavy one was not solved) gives the optimum again.
    sol, maps = cycle.solve(allegro, None)
    ref = solve(allegro, solver=make_solver('quadprog'))
    np.testing.assert_allclose(sol.tau, ref.tau, atol=1e-6)
    assert cycle.solver.warm_solves >= 1


def test_inputs_of_the_wrong_shape_are_handed_back_not_a_crash(allegro):
    cycle = compiled.CompiledCycle(allegro, TauQPSolver(), 1e-6)
    raw = cycle._cycle
    z = np.zeros
    a = raw.solve(z((4, 4, 4)), z((4, 6, 3)), z((4, 3)), z((4, 3)), z(4, dtype=bool),
                  z((4, 3)), z(4, dtype=bool), z(3), z(6), z(0), -1.0)
    assert a.code == loader.fast_cycle.NOT_HANDLED and a.message == 'joint index out of range'
    a = raw.solve(z((4, 4, 3)), z((4, 6, 16)), z((4, 3)), z((4, 3)), z(4, dtype=bool),
                  z((4, 3)), z(4, dtype=bool), z(3), z(6), z(0), -1.0)
    assert a.code == loader.fast_cycle.NOT_HANDLED and a.message == 'inputs of the wrong shape'


def test_a_grasp_with_internal_forces_runs_the_python_cycle(planar):
    fast, slow = fresh(planar), fresh(planar, compiled=False)
    qs = moving_states(planar, compiled.RANK_GIVE_UP + 5, scale=1e-3)
    got, ref = run(fast, planar, qs), run(slow, planar, qs)
    for a, b in zip(got, ref):
        assert a.kind == b.kind == 'solution'
        np.testing.assert_allclose(a.command, b.command, atol=1e-9)
    # Tried RANK_GIVE_UP times, then no more for this grasp.
    assert fast.compiled_cycle.handed_back == compiled.RANK_GIVE_UP
    assert 'not of full column rank' in dict(report(fast, 2.0).values)['solver.compiled']


def test_what_the_compiled_cycle_does_not_solve_is_said(allegro_doc, allegro):
    cases = {'tau-qp-adaptive': 'method tau-qp-adaptive'}
    for method, why in cases.items():
        assert compiled.unsupported(allegro, method, TauQPSolver()).startswith(why)
    assert compiled.unsupported(allegro, 'tau-qp',
                                make_solver('quadprog')).startswith('backend quadprog')
    minmax = dataclasses.replace(allegro, objective='min-max')
    assert compiled.unsupported(minmax, 'tau-qp', TauQPSolver()).startswith('objective min-max')
    assert compiled.unsupported(allegro, 'tau-qp', TauQPSolver()) == ''
    assert compiled.unsupported(allegro, 'tau-qp', make_solver('daqp')) == ''
    # A quadprog controller runs the Python cycle and says why.
    ctrl = fresh(allegro)
    ctrl.solver = make_solver('quadprog')
    ctrl.take('joint_states', JointStateReading(*joint_state(allegro)), 1.0)
    assert ctrl.cycle(1.0).kind == 'solution' and ctrl.compiled_cycle is None
    assert dict(report(ctrl, 2.0).values)['solver.compiled'].startswith(
        'false: backend quadprog')


def test_a_new_friction_or_weights_make_a_new_compiled_cycle(allegro):
    fast, slow = fresh(allegro), fresh(allegro, compiled=False)
    names, pos = joint_state(allegro)
    for ctrl in (fast, slow):
        ctrl.take('joint_states', JointStateReading(names, pos), 1.0)
        ctrl.cycle(1.0)
    first = fast.compiled_cycle
    weights = np.linspace(1.0, 3.0, allegro.hand.m)
    friction = dataclasses.replace(allegro.friction, mu1=0.6, margin=0.2)
    for ctrl in (fast, slow):
        ctrl.setup = dataclasses.replace(ctrl.setup, weights=weights, friction=friction)
        ctrl.take('joint_states', JointStateReading(names, pos), 1.1)
    a, b = fast.cycle(1.1), slow.cycle(1.1)
    assert fast.compiled_cycle is not first and fast.compiled_cycle.solves == 1
    assert a.kind == b.kind == 'solution'
    np.testing.assert_allclose(a.command, b.command, atol=1e-6)
    at = dataclasses.replace(allegro, weights=weights, friction=friction)
    qp = build_tau_qp(at.maps(), planned_friction(friction), at.external_wrench,
                      *at.tau_bounds, weights)
    assert a.solution.tau @ (qp.H @ a.solution.tau) == pytest.approx(
        b.solution.tau @ (qp.H @ b.solution.tau), rel=1e-7)


def test_a_contact_list_of_another_size_is_taken_cold(allegro_doc, allegro):
    # Four fingertips, then three (a finger lifted), then four again: the same compiled
    # cycle (same hand, friction, weights) meets a QP of another size and starts cold.
    three = setup_from_doc(with_contacts(allegro_doc, allegro_doc['grasp']['contacts'][:3]))
    fast, slow = fresh(allegro), fresh(allegro, compiled=False)
    names, pos = joint_state(allegro)
    certified = 0
    for k, contacts in enumerate([allegro.contacts, three.contacts, allegro.contacts]):
        results = []
        for ctrl in (fast, slow):
            ctrl.setup = dataclasses.replace(ctrl.setup, contacts=contacts)
            ctrl.take('joint_states', JointStateReading(names, pos), 1.0 + k)
            results.append(ctrl.cycle(1.0 + k))
        a, b = results
        assert a.kind == b.kind and a.solution.status == b.solution.status
        if a.kind == 'solution':
            certified += 1
            np.testing.assert_allclose(a.command, b.command, atol=1e-6)
        assert a.maps.G.shape == (6, 4 * len(contacts))
    assert certified >= 2  # four fingertips hold it; three may not
    assert fast.compiled_cycle.solves == certified and fast.compiled_cycle._cycle.inits == 3


@pytest.mark.parametrize('backend', BACKENDS)
@pytest.mark.parametrize('name', loader.MODULES)
def test_every_module_built_for_this_cpu_gives_the_python_optimum(allegro, name, backend):
    # The node loads the best of them; the other must be right as well (another CPU).
    module, why = loader.load(name)
    assert module is not None, why
    cycle = compiled.CompiledCycle(allegro, BACKENDS[backend][0](), 1e-6, module=module)
    assert cycle.module is module and cycle._cycle.uses_daqp == (backend == 'daqp')
    python = make_solver(backend)
    for q in moving_states(allegro, 60, seed=5):
        full = allegro.q.copy()
        full[allegro.hand.idx_q] = q
        at = dataclasses.replace(allegro, q=full)
        sol, maps = cycle.solve(at, None)
        ref = solve(at, solver=python)
        assert sol.optimal and ref.optimal
        np.testing.assert_allclose(sol.tau, ref.tau, atol=1e-6)
        np.testing.assert_allclose(sol.wrenches, ref.wrenches, atol=1e-6)
        # Within the certificate's tolerance (a warm answer sits up to ~1e-8 N outside the
        # polygon where the cold one is on it; both are solver-tolerance deep).
        assert sol.certificate.ok and sol.certificate.worst <= 1e-7
    assert cycle.solves == 60 and cycle.solver.warm_solves == 59
