# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The backends by name: each one's solver class, settings type and options.

:func:`make_solver` makes a backend from this table, the dispatcher and the
node's cycle tell a backend from a solver of the caller's own with
:func:`is_backend`: nothing is found by probing attributes.
"""

from __future__ import annotations

from dataclasses import dataclass
import importlib.util

from grasp_torque_opt.backends.base import Backend
from grasp_torque_opt.backends.daqp import DaqpSettings, DaqpSolver
from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings, TauQPSolver
from grasp_torque_opt.backends.quadprog import QuadprogSettings, QuadprogSolver


@dataclass(frozen=True)
class Entry:
    """
    One backend in the registry.

    Attributes:
        name: its name (``--backend``, ``solver.backend``).
        solver: its class, which implements :class:`~grasp_torque_opt.backends.base.Backend`.
        settings: its settings type, a frozen dataclass whose ``from_proxsuite``
            maps a :class:`ProxSuiteSettings` to it.
        module: the Python module it needs (:func:`available`).
        warm_start: it takes ``warm_start`` (a warm start of its own).
        sliced: it takes ``max_slice_s`` (ProxSuite's calls under a deadline).
    """

    name: str
    solver: type
    settings: type
    module: str
    warm_start: bool = False
    sliced: bool = False


#: The backends; the first is the default.
REGISTRY: dict[str, Entry] = {e.name: e for e in (
    Entry('proxsuite', TauQPSolver, ProxSuiteSettings, 'proxsuite', warm_start=True,
          sliced=True),
    Entry('daqp', DaqpSolver, DaqpSettings, 'daqp', warm_start=True),
    Entry('quadprog', QuadprogSolver, QuadprogSettings, 'quadprog'),
)}
#: Selectable backends; the first is the default.
BACKENDS = tuple(REGISTRY)
#: The registered solver classes (:func:`is_backend`).
_SOLVER_TYPES = tuple(e.solver for e in REGISTRY.values())


def entry(backend: str) -> Entry:
    """
    Return a backend's registry entry.

    Raises:
        ValueError: an unknown backend, naming the known ones.
    """
    try:
        return REGISTRY[backend]
    except (KeyError, TypeError):
        raise ValueError(f"backend must be one of {', '.join(BACKENDS)}, "
                         f'got {backend!r}') from None


def available(backend: str) -> bool:
    """
    Whether the Python module of a backend can be imported here.

    ProxSuite is a dependency; DAQP and quadprog are optional (pip installs them, a
    ROS distribution may not have them).
    """
    module = REGISTRY[backend].module if backend in REGISTRY else backend
    try:
        return importlib.util.find_spec(module) is not None
    except (ValueError, ImportError):  # e.g. blocked as sys.modules[name] = None
        return False


def settings_for(backend: str, settings: object | None = None) -> object:
    """
    Return the settings of a backend's own type.

    Args:
        backend: one of :data:`BACKENDS`.
        settings: None (the backend's defaults), the backend's own settings, or a
            :class:`ProxSuiteSettings` (the node's and the CLI's common form), mapped
            by the settings type's ``from_proxsuite`` (DAQP: ``eps_abs`` is its
            ``primal_tol``, ``max_iter`` its ``iter_limit``; quadprog: nothing).

    Raises:
        ValueError: an unknown backend.
        TypeError: settings of another backend's type.
    """
    kind = entry(backend).settings
    if settings is None:
        return kind()
    if isinstance(settings, kind):
        return settings
    if isinstance(settings, ProxSuiteSettings):
        return kind.from_proxsuite(settings)
    raise TypeError(f'settings for backend {backend} must be {kind.__name__} or '
                    f'ProxSuiteSettings, got {type(settings).__name__}')


def make_solver(backend: str = 'proxsuite', settings: object | None = None,
                warm_start: bool = False, max_slice_s: float | None = None) -> Backend:
    """
    Make a tau-QP solver by backend name (one of :data:`BACKENDS`).

    Args:
        backend: the backend's name.
        settings: its settings, or a :class:`ProxSuiteSettings` for any backend
            (:func:`settings_for`), or None for its defaults.
        warm_start: start each solve from the previous one, for a backend that has
            warm starts (ProxSuite and DAQP verify their warm answers and redo a bad
            one cold); quadprog has none.
        max_slice_s: longest ProxSuite call under a deadline [s]
            (:class:`~grasp_torque_opt.backends.proxsuite.TauQPSolver`); the other
            backends stop by the deadline without slices.

    Raises:
        ValueError: an unknown backend, naming the known ones, or one whose
            module is not installed, saying how to install it.
    """
    e = entry(backend)
    if not available(backend):
        raise ValueError(f'backend {backend!r} is not installed (pip install {e.module})')
    options = {}
    if e.warm_start:
        options['warm_start'] = warm_start
    if e.sliced:
        options['max_slice_s'] = max_slice_s
    return e.solver(settings_for(backend, settings), **options)


def is_backend(solver: object) -> bool:
    """
    Tell a registered backend (or a subclass of one) from a solver of the caller's own.

    A backend is asked with the whole :class:`~grasp_torque_opt.backends.base.Backend`
    protocol; a solver of the caller's own only as ``solve(qp)``.
    """
    return isinstance(solver, _SOLVER_TYPES)


class _OwnSolver:
    """
    A solver of the caller's own, seen as a :class:`~grasp_torque_opt.backends.base.Backend`.

    It is asked ``solve(qp)`` only: no deadline (its own caps bound it), no warm start,
    so no cold redo.
    """

    settings = None
    warm_start = last_warm = False

    def __init__(self, solver, name: str) -> None:
        self._solver, self.name = solver, name

    def solve(self, qp, cold: bool = False, deadline: float | None = None):
        """Ask the caller's solver (``cold`` and ``deadline`` do not reach it)."""
        return self._solver.solve(qp)


def as_backend(solver, name: str) -> Backend:
    """
    Return a backend as it is, and a solver of the caller's own in the protocol's form.

    Args:
        solver: a backend, or any object with ``solve(qp) -> RawResult``.
        name: the name reported for a solver of the caller's own that has no ``name``.
    """
    if is_backend(solver):
        return solver
    # The caller's own solver is duck-typed: its name is optional.
    return _OwnSolver(solver, getattr(solver, 'name', name))
