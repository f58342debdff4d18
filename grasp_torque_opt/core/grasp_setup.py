# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""A grasp problem bound to its hand: what every method solves."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
import warnings

from grasp_torque_opt.core.contact_links import check_contact_links
from grasp_torque_opt.core.exceptions import GeometryWarning, InputError
from grasp_torque_opt.core.grasp_maps import compute_grasp_maps, GraspMaps
from grasp_torque_opt.core.hand import Hand, resolve_urdf
from grasp_torque_opt.core.inward import check_inward_normals
from grasp_torque_opt.core.scenario import Friction, load_scenario, Scenario
from grasp_torque_opt.core.scenario_contacts import check_contact_points, resolve_contacts
from grasp_torque_opt.core.scenario_fields import ContactSpec
import numpy as np


@dataclass(frozen=True)
class GraspSetup:
    """
    Everything one solve needs.

    Attributes:
        hand: the hand (model, actuated joints, torque limits).
        q: full configuration, shape (nq,).
        contacts: contact specifications.
        object_origin: c, base frame [m].
        friction: friction model and linearization.
        external_wrench: w_ext, load on the object about c, base axes [N, N m].
        weights: W's diagonal, shape (m,), > 0.
        torque_offset: torque added to the solution before it is commanded, e.g.
            the fingers' own gravity torques g(q), shape (m,) [N m], or None.
            The torque limits then bound the sum: -limit <= tau + offset <= limit.
        objective: ``sum-of-squares`` (the paper's tau^T W tau) or ``min-max``
            (max_i w_i |tau_i + offset_i| / limit_i, docs/planner.md).
    """

    hand: Hand
    q: np.ndarray
    contacts: list[ContactSpec]
    object_origin: np.ndarray
    friction: Friction
    external_wrench: np.ndarray
    weights: np.ndarray
    torque_offset: np.ndarray | None = None
    objective: str = 'sum-of-squares'

    @property
    def tau_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(tau_min, tau_max) on the optimized torque [N m], after the offset."""
        lim = self.hand.torque_limits
        off = 0.0 if self.torque_offset is None else self.torque_offset
        return -lim - off, lim - off

    @classmethod
    def from_scenario(cls, scenario: Scenario, urdf_xml: str | None = None) -> GraspSetup:
        """
        Load the hand of a scenario and bind the scenario to it.

        Args:
            scenario: the validated scenario.
            urdf_xml: a URDF document to use instead of the scenario's
                ``hand.urdf`` (e.g. the node's ``robot_description``).

        Raises:
            InputError: naming the field (file, joint or frame not found, a contact
                normal pointing out of the object, ...); GeometryError: a contact given
                by link only (or ``auto``) not found from geometry.

        A contact point written by hand farther from the object's surface than
        ``grasp.contact_tolerance`` is a :class:`GeometryWarning`.
        """
        above = scenario.torque_limits_above_urdf
        if urdf_xml:
            urdf = urdf_xml
            hand = Hand.from_urdf_string(urdf_xml, scenario.joints, scenario.torque_limits,
                                         above, scenario.coupling, scenario.base_link)
        else:
            urdf = resolve_urdf(scenario.urdf, scenario.base_dir)
            hand = Hand.from_urdf(urdf, scenario.joints, scenario.torque_limits, above,
                                  scenario.coupling, scenario.base_link)
        weights = np.ones(hand.m) if scenario.weights is None else np.asarray(scenario.weights)
        if weights.shape != (hand.m,):
            raise InputError('objective.weights',
                             f'must have {hand.m} entries (one per joint), got {weights.size}')
        q = hand.configuration(scenario.joint_positions)
        # Names unknown frames, links that no joint moves and bad normals now, not at
        # solve time; contacts given by link only (or auto) found from geometry.
        check_contact_links(hand.model, [c.link for c in scenario.contacts],
                            base=hand.base_link)
        setup = cls(hand=hand, q=q, contacts=resolve_contacts(scenario, hand, q, urdf),
                    object_origin=scenario.object_origin,
                    friction=scenario.friction, external_wrench=scenario.external_wrench,
                    weights=weights, objective=scenario.objective)
        maps = setup.maps()
        check_inward_normals(maps.positions, maps.rotations[:, :, 2], maps.links,
                             scenario.object_origin, scenario.object)
        check_contact_points(scenario, maps.positions, [
            i for i, c in enumerate(scenario.contacts) if c.position is not None])
        return setup

    @classmethod
    def from_file(cls, path: str | Path) -> GraspSetup:
        """Read, validate and bind a scenario file."""
        return cls.from_scenario(load_scenario(path))

    def maps(self) -> GraspMaps:
        """Contact frames, G and J at this configuration."""
        return compute_grasp_maps(self.hand, self.q, self.contacts, self.object_origin)


def bind_for_candidates(scenario: Scenario) -> tuple[GraspSetup, list[Warning]]:
    """
    Bind a base scenario whose contacts candidates may replace (planning, scoring).

    Its contacts' :class:`GeometryWarning` s (points written for another object, the
    bundled sphere's with a box ``object``) are returned, not issued: the caller issues
    them when a candidate keeps those contacts.
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always', GeometryWarning)
        setup = GraspSetup.from_scenario(scenario)
    for w in caught:  # anything else is issued as it would have been
        if not issubclass(w.category, GeometryWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return setup, [w.message for w in caught if issubclass(w.category, GeometryWarning)]


def issue_once(caught: list[Warning]) -> None:
    """Issue the warnings :func:`bind_for_candidates` returned, then forget them."""
    for message in caught:
        warnings.warn(message, stacklevel=3)
    caught.clear()
