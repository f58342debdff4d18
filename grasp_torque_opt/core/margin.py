# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Friction margin and the numbers a planner reads off a solution (docs/planner.md).

A friction margin k >= 0 plans inside the soft-finger cone of mu1/(1+k) and
mu2/(1+k): every wrench planned (and certified) in that reduced cone uses at
most 1/(1+k) of the real, unreduced cone, so it still holds when the real
friction is up to (1+k) times lower than modelled. k = 0 is the unreduced cone.

Friction usage of a contact wrench f = [fx, fy, fz, mz] on a cone (mu1, mu2) is

    (||(fx, fy)|| / mu1 + |mz| / mu2) / fz,

the factor by which the cone could shrink before f leaves it: 1 on the cone,
0 for a pure push, inf when the finger does not press (fz <= 0). It is reported
on the unreduced cone, so with margin k a certified wrench reads at most 1/(1+k).

Only data and cone arithmetic here: no solver (the core's rule).
"""

from __future__ import annotations

import dataclasses

from grasp_torque_opt.core.scenario import Friction
import numpy as np


def planned_friction(friction: Friction) -> Friction:
    """
    Return the friction the optimization and the certificate use: the cone reduced by the margin.

    Returns:
        ``friction`` itself when its margin is 0, else a copy with mu1/(1+k),
        mu2/(1+k) and margin 0 (the reduced cone is then the one to respect).
    """
    k = friction.margin
    if k == 0.0:
        return friction
    return dataclasses.replace(friction, mu1=friction.mu1 / (1.0 + k),
                               mu2=friction.mu2 / (1.0 + k), margin=0.0)


def cone_usage(wrenches: np.ndarray, mu1: float, mu2: float) -> np.ndarray:
    """
    Friction usage per contact, (||f_t||/mu1 + |m_z|/mu2) / f_z [-].

    Args:
        wrenches: shape (p, 4), [fx, fy, fz, mz] per contact, contact frames [N, N m].
        mu1: tangential coefficient of the cone to measure against [-].
        mu2: torsional coefficient [m].

    Returns:
        Shape (p,); inf where f_z <= 0.
    """
    w = np.atleast_2d(np.asarray(wrenches, dtype=float))
    demand = np.hypot(w[:, 0], w[:, 1]) / mu1 + np.abs(w[:, 3]) / mu2
    with np.errstate(divide='ignore', invalid='ignore'):
        return np.where(w[:, 2] > 0.0, demand / np.where(w[:, 2] > 0.0, w[:, 2], 1.0), np.inf)


def torque_ratio(tau: np.ndarray, limits: np.ndarray, offset: np.ndarray | None = None,
                 weights: np.ndarray | None = None) -> float:
    """
    max_i w_i |tau_i + offset_i| / limit_i: how close the commanded torques come to a limit [-].

    Args:
        tau: optimized joint torques, shape (m,) [N m].
        limits: torque limits, shape (m,) [N m], > 0.
        offset: torque added before commanding (g(q)), shape (m,) [N m], or None.
        weights: per-joint factors (the min-max objective's), or None for ones.
    """
    commanded = np.asarray(tau, dtype=float) + (0.0 if offset is None else offset)
    ratio = np.abs(commanded) / np.asarray(limits, dtype=float)
    if weights is not None:
        ratio = ratio * weights
    return float(ratio.max())
