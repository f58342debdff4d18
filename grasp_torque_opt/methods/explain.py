# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Why a load is infeasible: the largest holdable fraction of it, and what binds there.

When no torque within the limits holds a load, the capacity LP of
:mod:`.capacity` still answers: alpha < 1 is the largest fraction of the load
that the grasp holds (certified at alpha), and the constraints with a nonzero
multiplier at that optimum are what stops it (joints at a torque limit,
contacts on their friction cone or at the minimum normal force, by name).
Each of them is active at every optimal point, so relaxing one of them (a larger
torque limit, more friction, a smaller minimum normal force) is where a larger
fraction can come from. When not even zero load is holdable there is no optimum:
the constraints named are then those of an infeasibility certificate
(:mod:`.infeasibility`), with the families whose removal would make it holdable.
"""

from __future__ import annotations

from dataclasses import dataclass

from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.methods.capacity import Capacity, load_capacity


@dataclass(frozen=True)
class Explanation:
    """
    What can be held of a load.

    Attributes:
        capacity: the capacity LP's answer for the load (``value`` is the fraction).
        text: one line for people.
    """

    capacity: Capacity

    @property
    def holdable_fraction(self) -> float | None:
        """Largest fraction of the load that is holdable [-], or None."""
        return self.capacity.value

    @property
    def text(self) -> str:
        """One line: the fraction and what binds, by name."""
        c = self.capacity
        if c.status == 'infeasible':
            return c.message
        if c.status != 'optimal':
            return f'no explanation: the capacity LP {c.status} ({c.message})'
        if c.value >= 1.0:
            return (f'the capacity LP finds the whole load holdable ({c.value:.4g} times over): '
                    "the solver's verdict and the LP disagree")
        return (f'at most {100 * c.value:.1f}% of this load can be held; there, '
                f'{c.binding.text()}')

    def as_dict(self) -> dict:
        """
        Return plain data (JSON).

        The keys are ``holdable_fraction``, ``binding``, ``relaxed`` (when not even
        zero load is holdable: constraint family -> holdable without it; else null),
        ``status``, ``certified`` and ``text``.
        """
        d = self.capacity.as_dict()
        return {'holdable_fraction': d['value'], 'status': d['status'],
                'certified': d['certified'], 'binding': d['binding'],
                'relaxed': None if self.capacity.conflict is None
                else dict(self.capacity.conflict.relaxed), 'text': self.text}


def explain(setup: GraspSetup, maps: GraspMaps | None = None) -> Explanation:
    """Find the largest holdable fraction of the setup's load and what binds there."""
    return Explanation(load_capacity(setup, maps))


def holdable(cap: Capacity, status: str) -> tuple[float | None, str | None]:
    """
    Return a scored candidate's holdable fraction and why its capacity is not ``optimal``.

    Args:
        cap: the capacity LP's answer for its load.
        status: the solve's status of that load.

    Returns:
        (the fraction: the capacity of an ``infeasible`` candidate, else None; the
        capacity's message unless ``optimal``, else None). A capacity of 1 or more for
        a load the solve found infeasible gives no fraction, and says so.
    """
    reason = None if cap.status == 'optimal' else cap.message
    fraction = cap.value if status == 'infeasible' else None
    if fraction is not None and fraction >= 1.0:  # the solve and the LP disagree
        return None, (f'the capacity LP holds {cap.value:.6g} times the load, which the '
                      'solve found infeasible')
    return fraction, reason
