"""Soft-finger friction: the paper's linearized cone S and the exact-cone margin.

Exact cone (contact frame, f = [fx, fy, fz, mz]):
    sqrt(fx^2 + fy^2) / mu1 + |mz| / mu2 <= fz.
Linearization: a regular N-gon inscribed in the cross-section, vertices at the
angles 2*pi*j/N of the contact frame's x-y plane; 2N inequalities (the paper's
Section 1, with its typo c_{c+1} read as c_{j+1}) and the normal bound
fz >= f_min.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import scipy.linalg


def cone_rows(mu1: float, mu2: float, sides: int) -> np.ndarray:
    """The 2N rows of one contact's linearized cone, S_c f_i <= 0.

    Args:
        mu1: tangential friction coefficient [-].
        mu2: torsional friction coefficient [m].
        sides: number of polygon sides N >= 3.

    Returns:
        Shape (2N, 4) on [fx, fy, fz, mz] in the contact frame; rows j (+mz)
        then rows j (-mz), j = 1..N.
    """
    if sides < 3:
        raise ValueError(f"polygon_sides must be >= 3, got {sides}")
    j = np.arange(1, sides + 1)
    s, c = np.sin(2 * np.pi * j / sides), np.cos(2 * np.pi * j / sides)
    s1, c1 = np.roll(s, -1), np.roll(c, -1)
    sN = np.sin(2 * np.pi / sides)
    common = np.column_stack((mu2 * (s1 - s), mu2 * (c - c1), np.full(sides, -mu1 * mu2 * sN)))
    plus = np.column_stack((common, np.full(sides, mu1 * sN)))
    minus = np.column_stack((common, np.full(sides, -mu1 * sN)))
    return np.vstack((plus, minus))


def contact_block(mu1: float, mu2: float, sides: int,
                  min_normal_force: float) -> tuple[np.ndarray, np.ndarray]:
    """One contact's constraints S_i f_i <= b_i: the 2N cone rows and -fz <= -f_min.

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
    """The paper's S for p contacts (block diagonal) and its right-hand side.

    Cached: the same friction gives the same (read-only) arrays every cycle.

    Returns:
        S, shape ((2N + 1) p, 4p), and b, shape ((2N + 1) p,): S f <= b.
    """
    S_i, b_i = contact_block(mu1, mu2, sides, min_normal_force)
    S, b = scipy.linalg.block_diag(*([S_i] * p)), np.tile(b_i, p)
    S.flags.writeable = b.flags.writeable = False
    return S, b


def cone_margin(wrenches: np.ndarray, mu1: float, mu2: float) -> np.ndarray:
    """Margin of each contact wrench inside the exact soft-finger cone.

    Args:
        wrenches: shape (p, 4), [fx, fy, fz, mz] per contact, contact frames [N, N m].

    Returns:
        fz - ||(fx, fy)|| / mu1 - |mz| / mu2 per contact, shape (p,) [N];
        >= 0 inside the cone.
    """
    w = np.atleast_2d(wrenches)
    return w[:, 2] - np.hypot(w[:, 0], w[:, 1]) / mu1 - np.abs(w[:, 3]) / mu2


def friction_usage(wrenches: np.ndarray, mu1: float, mu2: float) -> np.ndarray:
    """Share of the friction used per contact: columns |f_t|/(mu1 f_n), |m_z|/(mu2 f_n).

    Returns:
        Shape (p, 2); inf where f_n <= 0.
    """
    w = np.atleast_2d(wrenches)
    with np.errstate(divide="ignore", invalid="ignore"):
        fn = np.where(w[:, 2] > 0.0, w[:, 2], 0.0)
        return np.column_stack((np.hypot(w[:, 0], w[:, 1]) / (mu1 * fn),
                                np.abs(w[:, 3]) / (mu2 * fn)))
