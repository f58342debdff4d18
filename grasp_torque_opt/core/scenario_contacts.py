# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
A scenario's contacts bound: those given by link only or ``auto`` found from geometry.

With an ``object``, a contact given by its link only (``- link: link_3.0_tip``) has its
point and normal found from the hand's collision shapes and the object at the grasp's
joint positions (:class:`~grasp_torque_opt.core.geometry_contacts.GeometryContacts`);
``contacts: auto`` takes every link within ``grasp.contact_tolerance`` of the object.
A contact written in full is kept as written, and its point, farther from the object's
surface than the tolerance, is warned about (:class:`GeometryWarning`: bundled
benchmark candidates move the fingers and keep their points on purpose; an error would
refuse them).
"""

from __future__ import annotations

from pathlib import Path
import warnings

from grasp_torque_opt.core.exceptions import GeometryError, GeometryWarning
from grasp_torque_opt.core.geometry_contacts import GeometryContacts
from grasp_torque_opt.core.hand import Hand, resolve_urdf
from grasp_torque_opt.core.object_geometry import object_pose, ObjectShape, point_distance
from grasp_torque_opt.core.scenario import Scenario
from grasp_torque_opt.core.scenario_fields import ContactSpec
import numpy as np


def from_geometry(scenario: Scenario) -> bool:
    """Tell whether some of the scenario's contacts are found from geometry."""
    return scenario.contacts_auto or any(c.position is None for c in scenario.contacts)


def resolve_contacts(scenario: Scenario, hand: Hand, q: np.ndarray,
                     urdf: str | Path | None = None) -> list[ContactSpec]:
    """
    Return the scenario's contacts with every point and normal, in the scenario's order.

    Args:
        scenario: the validated scenario.
        hand: its hand.
        q: the grasp's full configuration.
        urdf: the URDF document or file the hand was built from (default: the
            scenario's ``hand.urdf``).

    Raises:
        GeometryError: ``auto`` finds no link in contact; a link given alone is not within
            the tolerance (naming its distance) or has no collision shapes; overlap.
    """
    if not from_geometry(scenario):
        return list(scenario.contacts)
    if urdf is None:
        urdf = resolve_urdf(scenario.urdf, scenario.base_dir)
    obj = scenario.object
    pose = object_pose(obj.position, obj.rpy)
    tol = scenario.contact_tolerance
    if scenario.contacts_auto:
        model = GeometryContacts.bind(hand, urdf, obj, tol)
        found = model.contacts(q, pose)
        if found.p == 0:
            near = sorted(model.distances(q, pose).items(), key=lambda kv: kv[1])[:3]
            shown = ', '.join(f'{link} {1e3 * d:.3g} mm' for link, d in near)
            raise GeometryError('grasp.contacts', f'auto: no link within '
                                f'grasp.contact_tolerance ({1e3 * tol:g} mm) of the object '
                                f'(nearest: {shown})')
        return found.specs()
    computed = [i for i, c in enumerate(scenario.contacts) if c.position is None]
    links = [scenario.contacts[i].link for i in computed]
    model = GeometryContacts.bind(hand, urdf, obj, tol, links=links,
                                  field='grasp.contacts')
    found = model.contacts(q, pose)
    by_link = dict(zip(found.links, range(found.p)))
    distances = None
    out = list(scenario.contacts)
    for i in computed:
        spec = scenario.contacts[i]
        k = by_link.get(spec.link)
        if k is None:
            distances = distances or model.distances(q, pose)
            raise GeometryError(f'grasp.contacts[{i}].link', f"'{spec.link}' does not touch the "
                                f'object: {1e3 * distances[spec.link]:.3g} mm from it, more '
                                f'than grasp.contact_tolerance ({1e3 * tol:g} mm)')
        out[i] = ContactSpec(link=spec.link, position=found.points_link[k].copy(),
                             normal=found.normals[k].copy(), tangent=spec.tangent)
    return out


def check_contact_points(scenario: Scenario, positions: np.ndarray,
                         written: list[int]) -> list[str]:
    """
    Warn about contact points written by hand that are off the object's surface.

    Args:
        scenario: the scenario (without ``object`` nothing is checked).
        positions: every contact point in the base frame, shape (p, 3) [m].
        written: the indices of the contacts written with a position.

    Returns:
        The warnings' messages (each also issued as a :class:`GeometryWarning`).
    """
    obj = scenario.object
    if obj is None:
        return []
    shape, pose = ObjectShape.from_spec(obj), object_pose(obj.position, obj.rpy)
    tol, out = scenario.contact_tolerance, []
    for i in written:
        d = point_distance(shape, pose, positions[i])
        if abs(d) > tol:
            where = 'outside' if d > 0.0 else 'inside'
            out.append(f'grasp.contacts[{i}].position: {1e3 * abs(d):.3g} mm {where} the '
                       f"object's {obj.shape} surface, more than grasp.contact_tolerance "
                       f'({1e3 * tol:g} mm): the contact is not where the object is (give '
                       'the link only to have it found from geometry)')
            warnings.warn(out[-1], GeometryWarning, stacklevel=3)
    return out
