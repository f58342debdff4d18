# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Minimum-effort grasp joint torques with linearized soft-finger friction cones.

The package is layered (docs/architecture.md); each family imports only the ones
below it:

- :mod:`~grasp_torque_opt.core`: the ROS-free, solver-free numerical core (scenario,
  hand model, contact frames, G and J, friction, the tau-QP's data, certificate,
  solution and its JSON form);
- :mod:`~grasp_torque_opt.backends` (ProxSuite, DAQP, quadprog on the tau-QP) and
  :mod:`~grasp_torque_opt.reference` (the reference methods and the feasibility LP);
- :mod:`~grasp_torque_opt.methods`: :func:`solve` over every method, and the comparison;
- :mod:`~grasp_torque_opt.control`: the node's cycle on plain arrays, its diagnostics;
  beside it :mod:`~grasp_torque_opt.sim`, the hand in MuJoCo (optional extra ``sim``);
- :mod:`~grasp_torque_opt.native`: the compiled cycle's extension and its loader;
- :mod:`~grasp_torque_opt.ros` (the ROS 2 node and demo driver) and
  :mod:`~grasp_torque_opt.cli` (the command line).

The names below are the public Python API; they are imported on first use, so
``import grasp_torque_opt`` itself loads nothing heavy.
"""

from __future__ import annotations

import importlib

from grasp_torque_opt.core.interrupt import quiet_interrupt_in_console_scripts

quiet_interrupt_in_console_scripts()

#: Public name -> module that defines it.
_EXPORTS = {
    'GraspSetup': 'grasp_torque_opt.core.grasp_setup',
    'load_scenario': 'grasp_torque_opt.core.scenario',
    'parse_scenario': 'grasp_torque_opt.core.scenario',
    'Scenario': 'grasp_torque_opt.core.scenario',
    'Solution': 'grasp_torque_opt.core.solution',
    'solution_dict': 'grasp_torque_opt.core.report',
    'GraspTorqueError': 'grasp_torque_opt.core.exceptions',
    'InputError': 'grasp_torque_opt.core.exceptions',
    'SolverError': 'grasp_torque_opt.core.exceptions',
    'GeometryError': 'grasp_torque_opt.core.exceptions',
    'GeometryContacts': 'grasp_torque_opt.core.geometry_contacts',
    'ObjectShape': 'grasp_torque_opt.core.object_geometry',
    'BACKENDS': 'grasp_torque_opt.backends',
    'make_solver': 'grasp_torque_opt.backends',
    'single_threaded_math': 'grasp_torque_opt.backends',
    'ProxSuiteSettings': 'grasp_torque_opt.backends.proxsuite',
    'METHODS': 'grasp_torque_opt.methods.dispatch',
    'Refiner': 'grasp_torque_opt.methods.adaptive',
    'AdaptiveSettings': 'grasp_torque_opt.methods.adaptive',
    'Bounds': 'grasp_torque_opt.core.bounds',
    'solve': 'grasp_torque_opt.methods.dispatch',
    'compare': 'grasp_torque_opt.methods.compare',
    # The planner's numbers (docs/planner.md).
    'load_capacity': 'grasp_torque_opt.methods.capacity',
    'direction_capacities': 'grasp_torque_opt.methods.capacity',
    'Capacity': 'grasp_torque_opt.methods.capacity',
    'explain': 'grasp_torque_opt.methods.explain',
    'ScoreJob': 'grasp_torque_opt.methods.score',
    'score_batch': 'grasp_torque_opt.methods.engines',
    'read_candidates': 'grasp_torque_opt.methods.engines',
    'rank': 'grasp_torque_opt.methods.ranking',
    'rank_key': 'grasp_torque_opt.methods.ranking',
    'format_table': 'grasp_torque_opt.methods.ranking',
    'plan_grasps': 'grasp_torque_opt.methods.plan',
    'PlanSettings': 'grasp_torque_opt.methods.plan',
    'PlanResult': 'grasp_torque_opt.methods.plan',
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    """Import a public name from its module on first use (PEP 562)."""
    if name not in _EXPORTS:
        raise AttributeError(f"module 'grasp_torque_opt' has no attribute {name!r}")
    value = getattr(importlib.import_module(_EXPORTS[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
