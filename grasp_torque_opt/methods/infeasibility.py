# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Why a grasp holds nothing: an infeasibility certificate of the zero load.

When not even zero load is holdable (the capacity LP of :mod:`.capacity` is
infeasible at alpha = 0), there is no optimum whose multipliers say what binds.
The conflict is then named by a Farkas certificate of the constraints

    G f = 0,   S f <= b (each contact's polygon rows, then -f_z <= -f_min),
    tau_min <= J^T f <= tau_max,

found as the dual of the elastic LP ``min sum(s) s.t. A f - s <= b, G f = 0, s >= 0``:
its optimal multipliers y >= 0 (with lambda) satisfy A^T y + G^T lambda = 0 and
b^T y < 0, so the rows with y_r > 0 cannot hold together. The certificate is
checked here (residual and sign) before it is reported as ``certified``.

Each constraint family is also dropped in turn (torque limits; the friction cones'
polygon rows; the minimum normal force) and the rest solved again (HiGHS): a family
whose removal makes zero load holdable is a cause a user can act on (stronger
motors, more friction or another contact placement, a smaller squeeze).
"""

from __future__ import annotations

from dataclasses import dataclass

from grasp_torque_opt.core.friction import friction_matrix
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.scenario import Friction
from grasp_torque_opt.methods.lp import linprog
import numpy as np

#: A multiplier is part of the certificate above this share of the largest one.
SUPPORT_RTOL = 1e-6
#: The constraint families dropped in turn, by name.
FAMILIES = ('torque_limits', 'friction', 'min_normal_force')
#: What dropping each family means, in words.
RELAXED = {'torque_limits': 'unlimited torques', 'friction': 'unlimited friction',
           'min_normal_force': 'no minimum normal force'}


@dataclass(frozen=True)
class Conflict:
    """
    The constraints that cannot hold together at zero load.

    Attributes:
        joints: (joint, ``upper`` or ``lower`` limit) in the certificate, largest
            multiplier first.
        contacts: (link, ``friction cone`` or ``min normal force``), largest first.
        relaxed: family -> whether zero load is holdable without it (None:
            undecided).
        certified: the Farkas certificate was checked (A^T y + G^T lambda = 0 to
            tolerance, b^T y < 0).
    """

    joints: list[tuple[str, str]]
    contacts: list[tuple[str, str]]
    relaxed: dict[str, bool | None]
    certified: bool

    def text(self, min_normal_force: float) -> str:
        """One sentence: what conflicts, and what relaxing would help."""
        cones = [c for c, k in self.contacts if k == 'friction cone']
        squeezed = [c for c, k in self.contacts if k != 'friction cone']
        parts = []
        if squeezed:
            parts.append(f'the minimum normal force ({min_normal_force:g} N) at '
                         + ', '.join(squeezed))
        if cones:
            parts.append('the friction cones of ' + ', '.join(cones))
        if self.joints:
            parts.append('the torque limits of ' + ', '.join(
                f'{j} ({s})' for j, s in self.joints))
        what = ' conflicts with '.join((parts[0], ' and '.join(parts[1:]))) if len(
            parts) > 1 else (parts[0] if parts else 'the constraints')
        helps = [RELAXED[name] for name in FAMILIES if self.relaxed.get(name)]
        useless = [RELAXED[name] for name in FAMILIES if self.relaxed.get(name) is False]
        tail = ''
        if helps:
            tail += '; holdable with ' + ' or with '.join(helps)
        if useless:
            tail += '; not holdable even with ' + ' or with '.join(useless)
        return f'not even zero load can be held: {what}{tail}'

    def as_dict(self) -> dict:
        """Plain data (JSON): ``joints``, ``contacts`` (as in ``binding``), ``relaxed``."""
        return {'joints': [{'joint': j, 'limit': s} for j, s in self.joints],
                'contacts': [{'link': c, 'constraint': k} for c, k in self.contacts],
                'relaxed': dict(self.relaxed), 'certified': self.certified}


def _feasible(A_ub: np.ndarray, b_ub: np.ndarray, G: np.ndarray) -> bool | None:
    res = linprog(np.zeros(G.shape[1]), A_ub=A_ub if A_ub.size else None,
                  b_ub=b_ub if A_ub.size else None, A_eq=G, b_eq=np.zeros(G.shape[0]),
                  bounds=(None, None), method='highs')
    return {0: True, 2: False}.get(res.status)


def zero_load_conflict(maps: GraspMaps, friction: Friction, joints: list[str],
                       tau_min: np.ndarray, tau_max: np.ndarray) -> Conflict | None:
    """
    Name the constraints that keep a grasp from holding even zero load.

    Args:
        maps: G and J of the grasp.
        friction: the planned friction (margin applied).
        joints: the actuated joints, the columns of J.
        tau_min, tau_max: bounds on J^T f [N m], shape (m,).

    Returns:
        The conflict, or None when zero load is holdable or HiGHS cannot decide.
    """
    G, J = maps.G, maps.J
    S, b_S = friction_matrix(maps.p, friction.mu1, friction.mu2, friction.sides,
                             friction.min_normal_force)
    nS, nf = S.shape[0], G.shape[1]
    fin_up, fin_lo = np.isfinite(tau_max), np.isfinite(tau_min)
    A = np.vstack((J.T[fin_up], -J.T[fin_lo], S))
    b = np.concatenate((tau_max[fin_up], -tau_min[fin_lo], b_S))
    rows = A.shape[0]
    res = linprog(np.concatenate((np.zeros(nf), np.ones(rows))),
                  A_ub=np.hstack((A, -np.eye(rows))), b_ub=b,
                  A_eq=np.hstack((G, np.zeros((G.shape[0], rows)))), b_eq=np.zeros(6),
                  bounds=[(None, None)] * nf + [(0.0, None)] * rows, method='highs')
    if res.status != 0 or res.fun <= 1e-9:
        return None
    y = np.clip(-np.asarray(res.ineqlin.marginals), 0.0, None)
    lam = np.linalg.lstsq(G.T, -(A.T @ y), rcond=None)[0]
    scale = max(1.0, float(np.abs(A).max()) * float(y.max()))
    certified = bool(np.abs(A.T @ y + G.T @ lam).max() <= 1e-7 * scale
                     and b @ y < -1e-9 * max(1.0, float(np.abs(b).max())))

    thresh = SUPPORT_RTOL * float(y.max())
    up_idx, lo_idx = np.flatnonzero(fin_up), np.flatnonzero(fin_lo)
    n_up, n_lo, per = up_idx.size, lo_idx.size, nS // maps.p
    weight: dict[tuple[str, str], float] = {}
    for r in np.flatnonzero(y > thresh):
        r = int(r)
        if r < n_up:
            key = (joints[up_idx[r]], 'upper')
        elif r < n_up + n_lo:
            key = (joints[lo_idx[r - n_up]], 'lower')
        else:
            i, kind = divmod(r - n_up - n_lo, per)
            key = (maps.links[i], 'min normal force' if kind == per - 1 else 'friction cone')
        weight[key] = weight.get(key, 0.0) + float(y[r])
    ranked = sorted(weight, key=lambda k: -weight[k])
    joint_rows = [k for k in ranked if k[1] in ('upper', 'lower')]
    contact_rows = [k for k in ranked if k[1] not in ('upper', 'lower')]

    is_fmin = np.zeros(nS, dtype=bool)
    is_fmin[per - 1::per] = True
    relaxed = {
        'torque_limits': _feasible(S, b_S, G),
        'friction': _feasible(np.vstack((J.T[fin_up], -J.T[fin_lo], S[is_fmin])),
                              np.concatenate((tau_max[fin_up], -tau_min[fin_lo],
                                              b_S[is_fmin])), G),
        'min_normal_force': _feasible(
            np.vstack((J.T[fin_up], -J.T[fin_lo], S[~is_fmin])),
            np.concatenate((tau_max[fin_up], -tau_min[fin_lo], b_S[~is_fmin])), G),
    }
    return Conflict(joint_rows, contact_rows, relaxed, certified)
