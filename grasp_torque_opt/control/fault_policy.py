# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The fault policy (docs/node.md, "Faults"): what is published when no certified command is.

A command is published only from a certified solution that passes the gate. When
a cycle cannot produce one, nothing new is published: the effort controller keeps
the last certified command. Once ``hold_time`` has passed since that command, the
policy applies: ``hold`` keeps publishing nothing, ``zero`` publishes zero torques.
The first certified solution after a fault is published at once (a recovery).
"""

from __future__ import annotations

from dataclasses import dataclass

from grasp_torque_opt.control.inputs.store import Counters
from grasp_torque_opt.control.parameters.generated import CycleConfig
from grasp_torque_opt.core.grasp_maps import GraspMaps
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.solution import Solution
import numpy as np


#: The contact wrenches of zero torques: none, whatever the contacts (rates.step_wrenches).
NO_WRENCH = np.zeros((0, 4))


@dataclass
class CycleResult:
    """
    What one cycle decided.

    Attributes:
        command: effort command to publish now, in ``joints`` order [N m], or None.
        kind: ``solution`` (a certified command), ``zero`` (the zero policy) or
            ``none`` (nothing published).
        solution: the solve, if one ran.
        maps: its kinematic maps.
        gravity_torque: g(q) added to the solution, or None.
        fault: why no certified command was published ('' when healthy).
        cycle_time: wall time of the cycle [s] (0 for the watchdog's results).
        wrenches: the contact wrenches of ``command`` when it is a step of the rate rule
            (the same combination of its ends' wrenches), else None (the solution's).
        q: the joint positions a certified command was solved at (its contact links'
            placements, for ~/contact_wrench).
        faded: for a step across a change of the contact set, the links of the command
            in force that are not in ``maps`` and their fading wrenches, shape (k, 4)
            (None: none).
    """

    command: np.ndarray | None
    kind: str
    solution: Solution | None = None
    maps: GraspMaps | None = None
    gravity_torque: np.ndarray | None = None
    fault: str = ''
    cycle_time: float = 0.0
    wrenches: np.ndarray | None = None
    q: np.ndarray | None = None
    faded: tuple[tuple[str, ...], np.ndarray] | None = None


class FaultPolicy:
    """
    The command in force, the fault in progress, and what a fault publishes.

    Args:
        setup: the grasp (its hand's joints and torque limits).
        config: ``hold_time`` and ``fault_policy``.
        counters: where faults, recoveries and commands are counted (shared).
    """

    def __init__(self, setup: GraspSetup, config: CycleConfig, counters: Counters) -> None:
        self.setup, self.config, self.counters = setup, config, counters
        #: Why no certified command is published ('' when healthy).
        self.fault = ''
        #: The last certified command [N m] and its time [s].
        self.last_command: np.ndarray | None = None
        self.last_command_time: float | None = None
        #: The last command returned for publishing, certified or the zero policy's: what
        #: the effort controller holds (it has no timeout) [N m].
        self.in_force: np.ndarray | None = None
        #: When the command in force was returned for publishing [s] (None: unknown).
        self.in_force_time: float | None = None
        #: The contact wrenches of the command in force, shape (p, 4) (``NO_WRENCH`` for
        #: zero torques; None: not known).
        self.in_force_wrenches: np.ndarray | None = None
        #: The links of those wrenches' contacts (None: not known): a step combines the
        #: wrenches link by link (rates.step_wrenches).
        self.in_force_links: tuple[str, ...] | None = None
        #: The last result, certified or not.
        self.last: CycleResult | None = None

    def committed(self, result: CycleResult, now: float, from_fallback: bool) -> None:
        """Take a certified command for publishing: it is in force, a fault is over."""
        if self.fault:
            self.counters.recoveries += 1
        self.fault = ''
        self.last_command, self.last_command_time = result.command, now
        self.in_force, self.in_force_time = result.command, now
        self.in_force_wrenches = (result.wrenches if result.wrenches is not None
                                  else getattr(result.solution, 'wrenches', None))
        self.in_force_links = (tuple(result.maps.links) if result.maps is not None else ()
                               if self.in_force_wrenches is not None
                               and self.in_force_wrenches.size == 0 else None)  # no contacts
        if result.faded is not None and self.in_force_wrenches is not None \
                and self.in_force_links is not None:
            # A step across a set change: the contacts fading out are in force too.
            self.in_force_links += result.faded[0]
            self.in_force_wrenches = np.vstack((self.in_force_wrenches, result.faded[1]))
        self.counters.commands += 1
        if from_fallback:
            self.counters.fallback_solves += 1
        self.last = result

    def faulted(self, now: float, reason: str, sol: Solution | None = None,
                maps: GraspMaps | None = None, g: np.ndarray | None = None) -> CycleResult:
        """
        Record a fault at ``now`` and return what to publish: nothing, or the zero policy's.

        Within ``hold_time`` of the last certified command nothing is published (it is
        held); after it, ``fault_policy`` decides.
        """
        if not self.fault:
            self.counters.faults += 1
        self.fault = reason
        held = (self.last_command_time is not None
                and now - self.last_command_time <= self.config.hold_time)
        if not held and self.config.fault_policy == 'zero':
            result = self._zero(reason, sol, maps, g)
            self.in_force_time = now
        else:
            result = CycleResult(None, 'none', sol, maps, g, reason)
        self.last = result
        return result

    def reconfigured(self, result: CycleResult | None, stale: str) -> CycleResult | None:
        """
        After a parameter change that gave no certified command: zero torques if needed.

        Zero torques are returned when the command in force exceeds the new torque
        limits, whatever ``fault_policy`` says (the effort controller would otherwise
        hold a torque the user has just forbidden).

        Args:
            result: the cycle run on the new parameters, or None (none could run).
            stale: why none could run ('' if one did).

        Returns:
            The result to publish, or None (nothing to publish now).
        """
        lim = self.setup.hand.torque_limits
        if self.in_force.shape == lim.shape and np.all(np.abs(self.in_force) <= lim):
            return result if result is not None and result.command is not None else None
        why = result.fault if result is not None else stale
        reason = 'the command in force exceeds the new torque_limits' + (
            f' ({why})' if why else '')
        if not self.fault:
            self.counters.faults += 1
        self.fault = reason
        self.last = self._zero(reason)
        return self.last

    def _zero(self, reason: str, sol: Solution | None = None, maps: GraspMaps | None = None,
              g: np.ndarray | None = None) -> CycleResult:
        """Return zero torques for publishing (then in force)."""
        cmd = np.zeros(self.setup.hand.m)
        self.counters.zero_commands += 1
        self.in_force = cmd
        self.in_force_wrenches = NO_WRENCH
        return CycleResult(cmd, 'zero', sol, maps, g, reason)
