# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Soft-finger friction: the paper's linearized cone S and the exact-cone margin.

Exact cone (contact frame, f = [fx, fy, fz, mz]):
    sqrt(fx^2 + fy^2) / mu1 + |mz| / mu2 <= fz.
Linearization: a regular N-gon inscribed in the cross-section, vertices at the
angles 2*pi*j/N of the contact frame's x-y plane; 2N inequalities (the paper's
Section 1, with its typo c_{c+1} read as c_{j+1}) and the normal bound
fz >= f_min.

Written per facet, the paper's row j is n_j . f_t / (mu1 cos(pi/N)) +- mz/mu2 <= fz
with n_j the unit normal of the polygon's edge j (at the angle 2*pi*(j + 1/2)/N):
the disc's norm ||f_t|| replaced by the polygon's gauge max_j n_j . f_t / cos(pi/N),
which is never smaller, so the polygon's cone lies inside the exact one.
The same N-gon scaled by 1/cos(pi/N) is circumscribed: its gauge max_j n_j . f_t
is never larger than ||f_t||, so its cone (:func:`circumscribed_rows`) contains
the exact one, torsion term included (that term is |mz|/mu2 in both, exactly);
any set of unit directions gives such an outer cone (:func:`tangent_rows`).
docs/adaptive.md uses both for certified bounds.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np


def cone_rows(mu1: float, mu2: float, sides: int) -> np.ndarray:
    """
    Return the 2N rows of one contact's linearized cone, S_c f_i <= 0.

    Args:
        mu1: tangential friction coefficient [-].
        mu2: torsional friction coefficient [m].
        sides: number of polygon sides N >= 3.

    Returns:
        Shape (2N, 4) on [fx, fy, fz, mz] in the contact frame; rows j (+mz)
        then rows j (-mz), j = 1..N.
    """
    if sides < 3:
        raise ValueError(f'polygon_sides must be >= 3, got {sides}')
    j = np.arange(1, sides + 1)
    s, c = np.sin(2 * np.pi * j / sides), np.cos(2 * np.pi * j / sides)
    s1, c1 = np.roll(s, -1), np.roll(c, -1)
    sN = np.sin(2 * np.pi / sides)
    common = np.column_stack((mu2 * (s1 - s), mu2 * (c - c1), np.full(sides, -mu1 * mu2 * sN)))
    plus = np.column_stack((common, np.full(sides, mu1 * sN)))
    minus = np.column_stack((common, np.full(sides, -mu1 * sN)))
    return np.vstack((plus, minus))


def circumscribed_rows(mu1: float, mu2: float, sides: int,
                       inflation: float = 0.0) -> np.ndarray:
    """
    Return the 2N rows of the circumscribed N-gon's cone, an outer approximation of the exact one.

    The paper's N-gon scaled by 1/cos(pi/N): each edge moved out until it touches
    the disc, so sqrt(fx^2 + fy^2)/mu1 + |mz|/mu2 <= fz implies every row.

    Args:
        mu1: tangential friction coefficient [-].
        mu2: torsional friction coefficient [m].
        sides: number of polygon sides N >= 3.
        inflation: the tangential and torsional coefficients divided by
            1 + inflation: a slightly larger cone, still an outer one, whose
            facets lie strictly inside the exact dual cone (docs/adaptive.md).

    Returns:
        Shape (2N, 4) on [fx, fy, fz, mz], rows n_j . f_t/mu1 + mz/mu2 - fz <= 0
        (j = 1..N, n_j at the angle 2*pi*(j + 1/2)/N, the normal of the paper's
        row j), then the same with -mz; fz's coefficient is -1.
    """
    if sides < 3:
        raise ValueError(f'polygon_sides must be >= 3, got {sides}')
    phi = 2 * np.pi * (np.arange(1, sides + 1) + 0.5) / sides
    directions = np.column_stack((np.cos(phi), np.sin(phi)))
    rows = tangent_rows(mu1, mu2, directions, inflation)
    return np.vstack((rows[:, 0], rows[:, 1]))


def tangent_rows(mu1: float, mu2: float, directions: np.ndarray,
                 inflation: float = 0.0) -> np.ndarray:
    """
    Facets of the exact cone along given tangential directions (an outer cone).

    For a unit u, u . f_t <= ||f_t||, so u . f_t/mu1 +- mz/mu2 <= fz holds on the
    whole exact cone and touches it along the direction u.

    Args:
        mu1: tangential friction coefficient [-].
        mu2: torsional friction coefficient [m].
        directions: unit tangential directions, shape (k, 2), contact frame.
        inflation: see :func:`circumscribed_rows`.

    Returns:
        Shape (k, 2, 4): per direction the +mz row, then the -mz row, on
        [fx, fy, fz, mz]; fz's coefficient is -1.
    """
    u = np.asarray(directions, dtype=float)
    a, b = 1.0 / (mu1 * (1.0 + inflation)), 1.0 / (mu2 * (1.0 + inflation))
    rows = np.empty((u.shape[0], 2, 4))
    rows[:, :, :2] = a * u[:, None, :]
    rows[:, :, 2] = -1.0
    rows[:, 0, 3], rows[:, 1, 3] = b, -b
    return rows


def dual_cone_margin(sigma: np.ndarray, mu1: float, mu2: float) -> np.ndarray:
    """
    How far each sigma lies inside the exact cone's dual cone K* [same unit as sigma].

    K = {fz >= ||f_t||/mu1 + |mz|/mu2} is generated by the rays (mu1 u, 1, 0) and
    (0, 0, 1, +-mu2), so K* = {s : s_z >= mu1 ||s_t|| and s_z >= mu2 |s_m|}.

    Args:
        sigma: shape (p, 4), [s_x, s_y, s_z, s_m] per contact.

    Returns:
        s_z - max(mu1 ||s_t||, mu2 |s_m|) per contact, shape (p,); >= 0 in K*.
    """
    s = np.atleast_2d(sigma)
    return s[:, 2] - np.maximum(mu1 * np.hypot(s[:, 0], s[:, 1]), mu2 * np.abs(s[:, 3]))


def contact_block(mu1: float, mu2: float, sides: int,
                  min_normal_force: float) -> tuple[np.ndarray, np.ndarray]:
    """
    One contact's constraints S_i f_i <= b_i: the 2N cone rows and -fz <= -f_min.

    Returns:
        S_i, shape (2N + 1, 4), and b_i, shape (2N + 1,) [N].
    """
    S_i = np.vstack((cone_rows(mu1, mu2, sides), [0.0, 0.0, -1.0, 0.0]))
    b_i = np.zeros(2 * sides + 1)
    b_i[-1] = -min_normal_force
    return S_i, b_i


@lru_cache(maxsize=64)
def friction_matrix(p: int, mu1: float, mu2: float, sides: int,
                    min_normal_force: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the paper's S for p contacts (block diagonal) and its right-hand side.

    Cached: the same friction gives the same (read-only) arrays every cycle.

    Returns:
        S, shape ((2N + 1) p, 4p), and b, shape ((2N + 1) p,): S f <= b.
    """
    S_i, b_i = contact_block(mu1, mu2, sides, min_normal_force)
    rows, cols = S_i.shape
    S, b = np.zeros((rows * p, cols * p)), np.tile(b_i, p)
    for i in range(p):  # block diagonal (SciPy's block_diag: its import is 0.2 s)
        S[i * rows:(i + 1) * rows, i * cols:(i + 1) * cols] = S_i
    S.flags.writeable = b.flags.writeable = False
    return S, b


def cone_margin(wrenches: np.ndarray, mu1: float, mu2: float) -> np.ndarray:
    """
    Margin of each contact wrench inside the exact soft-finger cone.

    Args:
        wrenches: shape (p, 4), [fx, fy, fz, mz] per contact, contact frames [N, N m].

    Returns:
        fz - ||(fx, fy)|| / mu1 - |mz| / mu2 per contact, shape (p,) [N];
        >= 0 inside the cone.
    """
    w = np.atleast_2d(wrenches)
    return w[:, 2] - np.hypot(w[:, 0], w[:, 1]) / mu1 - np.abs(w[:, 3]) / mu2


def friction_usage(wrenches: np.ndarray, mu1: float, mu2: float) -> np.ndarray:
    """
    Share of the friction used per contact: columns |f_t|/(mu1 f_n), |m_z|/(mu2 f_n).

    Returns:
        Shape (p, 2); inf where f_n <= 0.
    """
    w = np.atleast_2d(wrenches)
    with np.errstate(divide='ignore', invalid='ignore'):
        fn = np.where(w[:, 2] > 0.0, w[:, 2], 0.0)
        return np.column_stack((np.hypot(w[:, 0], w[:, 1]) / (mu1 * fn),
                                np.abs(w[:, 3]) / (mu2 * fn)))
