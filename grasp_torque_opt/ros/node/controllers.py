# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The node's two controllers, made from the parameters: one function for start and change.

The loop's controller runs the cycle on each joint state (warm started); the
service's solves ``~/solve`` requests on snapshots of the inputs, always cold and in
slices, with Pinocchio data and a solver workspace of its own.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from grasp_torque_opt.backends import available, make_solver
from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings
from grasp_torque_opt.backends.registry import entry, is_backend, settings_for
from grasp_torque_opt.control import compiled
from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.control.parameters.snapshot import cycle_config
from grasp_torque_opt.control.parameters.validators import stated_margin
from grasp_torque_opt.core.grasp_setup import GraspSetup
import numpy as np

#: Longest ProxSuite call of a ``~/solve`` request [s]: the service's worker shares
#: Python's interpreter lock with the control loop, which ProxSuite holds while it runs.
SERVICE_SLICE_S = 0.005


def fallback_backend(backend: str, fallback: str) -> str | None:
    """
    Name the fallback backend to build, or None.

    None for 'none', the backend itself, or one not installed (a ROS distribution may
    lack DAQP; the node then runs without a second try).
    """
    return None if fallback in ('none', backend) or not available(fallback) else fallback


def setup_of(setup: GraspSetup, p: Any, obj: Any = None) -> GraspSetup:
    """
    Give the grasp with the parameters' friction, weights, limits, objective, origin.

    The friction margin is the larger of ``friction_margin`` and the one the stated
    uncertainty asks (:func:`~grasp_torque_opt.control.parameters.validators.stated_margin`;
    ``obj``: the scenario's object, whose radius the pose uncertainty needs).
    """
    margin = p.friction_margin
    stated = stated_margin({'uncertainty.friction': p.uncertainty.friction,
                            'uncertainty.pose': p.uncertainty.pose,
                            'uncertainty.tip_radius': p.uncertainty.tip_radius,
                            'mu_tangential': p.mu_tangential}, obj)
    if stated is not None:
        margin = max(margin, stated)
    hand = setup.hand
    if not np.array_equal(hand.torque_limits, p.torque_limits):
        hand = dataclasses.replace(hand, torque_limits=np.array(p.torque_limits))
    return dataclasses.replace(
        setup, hand=hand, object_origin=np.array(p.object_origin),
        weights=np.array(p.weights), objective=p.objective,
        friction=dataclasses.replace(setup.friction, mu1=p.mu_tangential,
                                     mu2=p.mu_torsional, sides=p.polygon_sides,
                                     min_normal_force=p.min_normal_force,
                                     margin=margin))


def solver_settings(p: Any) -> ProxSuiteSettings:
    """Give the solver settings of the parameters (each backend takes what it has)."""
    return ProxSuiteSettings(eps_abs=p.solver.eps_abs, max_iter=p.solver.max_iter,
                             max_iter_in=p.solver.max_iter_in)


def configure(ctrl: TorqueController | None, setup: GraspSetup, p: Any,
              service: bool = False, obj: Any = None) -> TorqueController:
    """
    Make a controller from the parameters, or bring one to them in place.

    In place (a parameter change), the controller keeps its inputs, its last command
    and its counters; its solvers are made again only when their backend, settings or
    warm start changed (a new one starts cold).

    Args:
        ctrl: the controller to change, or None to make one.
        setup: the grasp as loaded (the parameters' values go over it).
        p: the parameters (a frozen snapshot,
            :class:`~grasp_torque_opt.control.parameters.generated.Params`).
        service: the service's controller (cold, in slices) instead of the loop's.
        obj: the scenario's object (the stated pose uncertainty's radius).

    Returns:
        The controller.
    """
    backend = p.solver.backend
    # A backend without warm starts of its own (quadprog) is made without one.
    warm = not service and p.solver.warm_start and entry(backend).warm_start
    slice_s = SERVICE_SLICE_S if service else None
    settings = solver_settings(p)
    fallback = fallback_backend(backend, p.solver.fallback)
    config = cycle_config(p)
    if ctrl is None:
        if service:  # its own Pinocchio data
            setup = dataclasses.replace(setup, hand=dataclasses.replace(setup.hand))
        ctrl = TorqueController(setup_of(setup, p, obj), config, settings, backend, warm, fallback)
        if service:
            ctrl.solver = make_solver(backend, settings, False, slice_s)
        return ctrl
    ctrl.setup, ctrl.config = setup_of(ctrl.setup, p, obj), config
    # Each backend holds its own settings type: compare in it. (A solver of one's own,
    # set on the controller, meets no backend's settings: it is replaced.)
    solver = ctrl.solver
    if not is_backend(solver) or settings_for(backend, settings) != solver.settings or \
            backend != solver.name or warm != solver.warm_start:
        ctrl.solver = make_solver(backend, settings, warm, slice_s)
    if fallback != getattr(ctrl.fallback, 'name', None) or \
            (ctrl.fallback is not None and
             ctrl.fallback.settings != settings_for(fallback, settings)):
        ctrl.fallback = make_solver(fallback, settings) if fallback else None
    return ctrl


def cycle_kind(ctrl: TorqueController) -> str:
    """Say which cycle runs: compiled, or Python and why."""
    if not ctrl.config.compiled:
        return 'Python (solver.compiled false)'
    why = compiled.unsupported(ctrl.setup, ctrl.config.method, ctrl.solver)
    return f'Python ({why})' if why else 'compiled'
