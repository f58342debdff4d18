# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The backend registry and protocol: every backend is made, configured and called alike."""

import dataclasses
import inspect

from grasp_torque_opt.backends import (
    as_backend,
    available,
    Backend,
    BACKENDS,
    DaqpSettings,
    is_backend,
    make_solver,
    ProxSuiteSettings,
    QuadprogSettings,
    REGISTRY,
    settings_for,
)
from grasp_torque_opt.core.tau_qp import build_tau_qp
import pytest


def test_backends_are_the_registry_in_order_the_default_first():
    assert BACKENDS == tuple(REGISTRY) and BACKENDS[0] == 'proxsuite'
    assert set(BACKENDS) == {'proxsuite', 'daqp', 'quadprog'}


@pytest.mark.parametrize('backend', BACKENDS)
def test_every_backend_satisfies_the_protocol(backend):
    entry = REGISTRY[backend]
    solver = make_solver(backend)
    assert isinstance(solver, Backend) and is_backend(solver)
    assert type(solver) is entry.solver and solver.name == backend
    assert type(solver.settings) is entry.settings
    assert dataclasses.is_dataclass(solver.settings)
    assert entry.settings.__dataclass_params__.frozen
    assert solver.warm_start is False and solver.last_warm is False
    params = inspect.signature(entry.solver.solve).parameters
    assert list(params)[:4] == ['self', 'qp', 'cold', 'deadline']
    assert params['cold'].default is False and params['deadline'].default is None


@pytest.mark.parametrize('backend', BACKENDS)
def test_every_backend_answers_the_same_call(backend, allegro):
    maps = allegro.maps()
    qp = build_tau_qp(maps, allegro.friction, allegro.external_wrench, *allegro.tau_bounds,
                      allegro.weights)
    raw = make_solver(backend).solve(qp, cold=True, deadline=None)
    assert raw.status == 'solved' and raw.x.shape == (qp.H.shape[0],)


def test_settings_have_a_type_per_backend():
    kinds = {REGISTRY[b].settings for b in BACKENDS}
    assert kinds == {ProxSuiteSettings, DaqpSettings, QuadprogSettings}


def test_proxsuite_settings_map_to_each_backends_own():
    prox = ProxSuiteSettings(eps_abs=1e-7, max_iter=77, max_iter_in=9, eps_rel=1e-3)
    assert settings_for('proxsuite', prox) is prox
    assert settings_for('daqp', prox) == DaqpSettings(primal_tol=1e-7, iter_limit=77)
    assert settings_for('quadprog', prox) == QuadprogSettings()


def test_defaults_and_own_settings_pass_through():
    assert settings_for('proxsuite') == ProxSuiteSettings()
    assert settings_for('daqp') == DaqpSettings.from_proxsuite(ProxSuiteSettings())
    own = DaqpSettings(primal_tol=1e-6, iter_limit=5)
    assert settings_for('daqp', own) is own


def test_settings_of_another_backend_are_refused():
    with pytest.raises(TypeError, match='settings for backend quadprog must be '
                                        'QuadprogSettings or ProxSuiteSettings, got DaqpSettings'):
        settings_for('quadprog', DaqpSettings())


def test_make_solver_converts_the_nodes_proxsuite_settings():
    """The node passes ProxSuiteSettings whatever the backend, positionally."""
    prox = ProxSuiteSettings(eps_abs=1e-8, max_iter=50)
    daqp = make_solver('daqp', prox, True, 0.001)
    assert daqp.settings == DaqpSettings(primal_tol=1e-8, iter_limit=50) and daqp.warm_start
    quadprog = make_solver('quadprog', prox, True, 0.001)
    assert quadprog.settings == QuadprogSettings() and quadprog.warm_start is False
    proxsuite = make_solver('proxsuite', prox, True, 0.001)
    assert proxsuite.settings is prox and proxsuite.warm_start
    assert proxsuite.max_slice_s == 0.001


def test_unknown_and_missing_backends_say_what_to_do(monkeypatch):
    with pytest.raises(ValueError, match='backend must be one of proxsuite, daqp, quadprog, '
                                         "got 'osqp'"):
        make_solver('osqp')
    monkeypatch.setitem(REGISTRY, 'daqp', dataclasses.replace(REGISTRY['daqp'],
                                                              module='no_such_module_here'))
    assert not available('daqp')
    with pytest.raises(ValueError, match=r'not installed \(pip install no_such_module_here\)'):
        make_solver('daqp')


class _Own:
    """A solver of the caller's own: only solve(qp)."""

    def __init__(self):
        self.calls = []

    def solve(self, qp):
        self.calls.append(qp)
        return 'answer'


def test_a_callers_own_solver_is_asked_plainly():
    own = _Own()
    seen = as_backend(own, 'proxsuite')
    assert not is_backend(own) and isinstance(seen, Backend)
    assert seen.name == 'proxsuite' and seen.warm_start is False and seen.last_warm is False
    assert seen.solve('qp', cold=True, deadline=1.0) == 'answer' and own.calls == ['qp']
    own.name = 'mine'
    assert as_backend(own, 'proxsuite').name == 'mine'


def test_a_backend_is_its_own_protocol_form():
    solver = make_solver('proxsuite')
    assert as_backend(solver, 'other') is solver
