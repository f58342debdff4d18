# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
Where the node's grasp comes from: the URDF, the scenario and the name map.

The URDF is ``robot_description`` (a document or a path), else the one published on
``robot_description_topic`` (waited for a bounded time), else the scenario's
``hand.urdf``. The scenario's names are mapped by ``name_map`` before they are checked
against the URDF.
"""

from __future__ import annotations

from collections.abc import Callable
import dataclasses
from dataclasses import dataclass
import time
from typing import Any

from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.control.geometry import ContactTracker
from grasp_torque_opt.control.motion import Motion, motion_wrench
from grasp_torque_opt.control.parameters.validators import name_map_of
from grasp_torque_opt.core.exceptions import FrameNotFound, InputError, JointNotFound
from grasp_torque_opt.core.geometry_contacts import GeometryContacts
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import MAX_URDF_BYTES, resolve_urdf
from grasp_torque_opt.core.link_surfaces import LinkSurfaces
from grasp_torque_opt.core.object_from_hand import ObjectFromHand
from grasp_torque_opt.core.object_geometry import object_pose
from grasp_torque_opt.core.resources import decode_utf8, find_config, read_bounded
from grasp_torque_opt.core.scenario import load_scenario, Scenario, weight_wrench
from grasp_torque_opt.native.loader import fast_cycle
from grasp_torque_opt.ros.node.parameters import PARAMETERS
from grasp_torque_opt.ros.node.qos import URDF_QOS
import numpy as np
from rclpy.node import Node
from rclpy.serialization import deserialize_message
from std_msgs.msg import String

#: Serialized std_msgs/String beyond the URDF's own bytes (CDR header, length, NUL).
URDF_MESSAGE_OVERHEAD = 64


@dataclass(frozen=True)
class Grasp:
    """
    A scenario bound to its hand, as the node loaded it.

    Attributes:
        scenario: the scenario file, its names mapped.
        setup: bound to the hand's model.
    """

    scenario: Scenario
    setup: GraspSetup


def wait_for_urdf(node: Node, topic: str, timeout: float,
                  stop: Callable[[], bool] = lambda: False) -> str:
    """
    Take the URDF from a robot_description topic, waiting for it up to ``timeout``.

    The subscription is reliable and transient local, as robot_state_publisher
    publishes it, so a URDF published before the node started arrives too. The
    message is taken serialized and refused by its length before it is deserialized.
    It polls (every 20 ms) instead of spinning, so it also works from inside a
    callback of the node's executor (the managed node's configure), which it then
    holds for at most ``timeout``.

    Args:
        node: the node that subscribes (for as long as this waits).
        topic: the topic (relative names resolve in the node's namespace).
        timeout: how long to wait [s].
        stop: polled; True ends the wait (a stop signal).

    Returns:
        The URDF document.

    Raises:
        InputError: nothing arrived in time, or the message is larger than a URDF may be
            (field ``robot_description_topic``).
    """
    sub = node.create_subscription(String, topic, lambda _: None, URDF_QOS, raw=True)
    name = sub.topic_name
    end = time.monotonic() + timeout
    try:
        while True:
            with sub.handle:
                taken = sub.handle.take_message(String, True)
            if taken is not None:
                data = taken[0]
                if len(data) > MAX_URDF_BYTES + URDF_MESSAGE_OVERHEAD:
                    raise InputError('robot_description_topic', f'the URDF on {name} is '
                                     f'{len(data)} bytes serialized, larger than a URDF may '
                                     f'be ({MAX_URDF_BYTES} bytes)')
                return deserialize_message(data, String).data
            if stop():
                raise InputError('robot_description_topic', f'stopped while waiting for the '
                                 f'URDF on {name}')
            if time.monotonic() >= end:
                raise InputError('robot_description_topic', f'no URDF on {name} within '
                                 f'{timeout:g} s (robot_description_timeout); it is taken '
                                 'reliable and transient local, as robot_state_publisher '
                                 'publishes it')
            time.sleep(0.02)
    finally:
        node.destroy_subscription(sub)


def urdf_document(node: Node, value: Callable[[str], object],
                  stop: Callable[[], bool] = lambda: False) -> str:
    """
    Give the URDF document to use: '' for the scenario's ``hand.urdf``.

    ``robot_description`` (a document or a path) wins; else, with
    ``robot_description_topic`` set, the URDF published there (waited for up to
    ``robot_description_timeout``); else the scenario's.

    Args:
        node: the node (its logger; it subscribes to the topic while it waits).
        value: a parameter's value by name (None while it has none).
        stop: polled while waiting; True ends the wait.
    """
    urdf = value('robot_description') or ''
    topic = value('robot_description_topic') or ''
    if urdf:
        if topic:
            node.get_logger().info(f'robot_description is set: the URDF on {topic} is '
                                   'not read')
        if not urdf.lstrip().startswith('<'):
            path = find_config(urdf, 'robot_description')
            urdf = decode_utf8(read_bounded(path, 'robot_description', MAX_URDF_BYTES),
                               path, 'robot_description')
        return urdf
    if topic:
        PARAMETERS.check('robot_description_topic', topic)
        timeout = value('robot_description_timeout')
        node.get_logger().info(f'waiting for the URDF on {topic} (up to {timeout:g} s)')
        return wait_for_urdf(node, topic, timeout, stop)
    return ''


def permuted(scenario: Scenario) -> list[tuple[str, str]]:
    """
    Give the scenario's joints that its name map sends to another of its joints' names.

    Such a map (a swap, a cycle) reorders the command without any name going missing.

    Returns:
        (scenario name, the name it is mapped to), in the scenario's order.
    """
    names = scenario.name_map
    inverse = {v: k for k, v in names.items()}
    before = [inverse.get(j, j) for j in scenario.joints]
    known = set(before)
    return [(k, names[k]) for k in before if names.get(k, k) != k and names[k] in known]


def bind(scenario_name: str | None, name_map: list[str] | None, urdf: str,
         joints: list[str] | None = None, joints_given: bool = False) -> Grasp:
    """
    Load the scenario, map its names (``name_map``) and bind it to the hand.

    Args:
        scenario_name: the ``scenario`` parameter (a path or a bundled name).
        name_map: the ``name_map`` parameter (None: none).
        urdf: the URDF document ('' for the scenario's ``hand.urdf``).
        joints: actuated joints in command order instead of the scenario's (URDF
            names), or None.
        joints_given: the ``joints`` parameter was given (the caller binds again with
            it): a name map that permutes the scenario's joints is then allowed.

    Raises:
        InputError: naming the parameter or the scenario's field; ``joints`` when the
            name map permutes the scenario's joints and ``joints`` is not given.
    """
    if not scenario_name:
        raise InputError('scenario', 'parameter not set (a scenario file gives the '
                         'default contacts and load)')
    scenario = load_scenario(find_config(scenario_name), name_map_of(name_map))
    swapped = permuted(scenario) if joints is None and not joints_given else []
    if swapped:
        a, b = swapped[0]
        raise InputError('joints', f"must be given: the name map sends the scenario's joint "
                         f"'{a}' to '{b}', the name of another of its joints, which would "
                         'reorder the command silently; set joints to the effort '
                         "controller's joint order")
    bound = scenario if joints is None else dataclasses.replace(scenario, joints=list(joints))
    try:
        setup = GraspSetup.from_scenario(bound, urdf or None)
    except (JointNotFound, FrameNotFound) as e:
        if not urdf:
            raise
        raise InputError(e.field, f'{e.problem}; if the scenario names them as another '
                         "URDF of this hand does, map them to this URDF's names with the "
                         'name_map parameter (SCENARIO_NAME=URDF_NAME) or the '
                         "scenario's hand.name_map") from e
    return Grasp(scenario, setup)


def load_of_gravity(scenario: Scenario) -> Callable[[np.ndarray], np.ndarray] | None:
    """
    Give the scenario's load as a function of gravity [m/s^2], or None.

    With ``at`` (the object and its origin at the object_pose input's pose), the load is
    applied there. With a :class:`~grasp_torque_opt.control.motion.Motion` (the IMU's),
    the load is the object's on the moving base
    (:func:`~grasp_torque_opt.control.motion.motion_wrench`).

    Only when the scenario's load is its object's weight (``object`` and ``gravity``
    both given): then it is ``load.external_wrench`` plus the weight under the gravity
    given, about the scenario's object origin, base axes. Otherwise the load does not
    depend on gravity.
    """
    if scenario.object is None or scenario.gravity is None:
        return None
    obj, origin = scenario.object, scenario.object_origin.copy()
    extra = scenario.extra_wrench.copy()

    def load(g: np.ndarray, motion: Motion | None = None,
             at: tuple[Any, np.ndarray] | None = None) -> np.ndarray:
        # at: the object and its origin moved (the object_pose input), else the scenario's.
        o, c = (obj, origin) if at is None else at
        if motion is not None:  # the apparent gravity g and the base's rotation
            return extra + motion_wrench(o, c, motion)
        return extra + weight_wrench(o, np.asarray(g, dtype=float), c)
    return load


def weight_of(scenario: Scenario) -> float | None:
    """Return the scenario's object's weight [N], or None (no object or no gravity)."""
    if scenario.object is None or scenario.gravity is None:
        return None
    return float(scenario.object.mass * np.linalg.norm(scenario.gravity))


def place_object(ctrl: TorqueController, scenario: Scenario, p: Any, urdf: str) -> None:
    """
    Give a controller the scenario's object, its pose, and the contacts from geometry.

    With ``contact_geometry.enabled`` the contact model is bound here, once (each
    controller its own: it keeps a Pinocchio workspace).

    Raises:
        InputError: ``contact_geometry.enabled`` without the scenario's object; a
            candidate link unknown or without collision geometry; a bad URDF.
    """
    obj = scenario.object
    pose = None if obj is None else object_pose(obj.position, obj.rpy)
    ctrl.solving.object, ctrl.solving.scenario_pose = obj, pose
    ctrl.store.scenario_pose = pose
    ctrl.solving.tracker = None
    ctrl.store.hand_object = ctrl.solving.hand_object = None
    if pose is not None:  # where the fingertips place it, from the scenario's grasp (its start)
        setup = ctrl.setup
        ctrl.store.hand_object, ctrl.solving.hand_object = (
            ObjectFromHand(setup.hand, setup.contacts, setup.q, pose, module=fast_cycle)
            for _ in range(2))
    if not p.contact_geometry.enabled:
        return
    if obj is None:
        raise InputError('contact_geometry.enabled', "needs the scenario's object (its "
                         'shape and pose): the scenario has none')
    links = list(p.contact_geometry.links) or [c.link for c in scenario.contacts]
    model = GeometryContacts.bind(
        ctrl.setup.hand, urdf or resolve_urdf(scenario.urdf, scenario.base_dir), obj,
        p.contact_geometry.tolerance, None if links == ['auto'] else links,
        field='contact_geometry.links')
    ctrl.solving.tracker = ContactTracker(model, obj)


def bind_scenario(ctrls: tuple[TorqueController, ...], scenario: Scenario, p: Any,
                  urdf: str) -> str:
    """
    Give controllers what the node's cycle takes from the scenario beyond the grasp.

    Its load as a function of gravity, its object (pose, the fingertips' estimate,
    contacts from geometry: :func:`place_object`), the links' collision shapes
    (:func:`bind_surfaces`) and its weight (the effort estimation's bound and the object
    loop's). The node does this for its loop's and its service's controllers;
    ``bench/cycle.py --params`` for its own.

    Returns:
        :func:`bind_surfaces`' warning ('' for none).

    Raises:
        InputError: as :func:`place_object`.
    """
    for c in ctrls:
        c.load_of_gravity = load_of_gravity(scenario)
        c.store.object = scenario.object
        place_object(c, scenario, p, urdf)
    bare = bind_surfaces(ctrls, scenario, urdf)
    for c in ctrls:
        c.solving.weight = weight_of(scenario)
    return bare


def bind_surfaces(ctrls: tuple[TorqueController, ...], scenario: Scenario, urdf: str) -> str:
    """
    Give controllers the links' collision shapes their contact checks use; say what lacks them.

    Returns:
        A warning to log once ('' when every link a joint moves has collision shapes):
        the links checked by ``max_contact_link_distance`` instead, or why no shape could
        be read (then every link is).
    """
    try:
        surfaces = [LinkSurfaces.bind(c.setup.hand, urdf or resolve_urdf(
            scenario.urdf, scenario.base_dir)) for c in ctrls]
    except InputError as e:
        for c in ctrls:
            c.store.surfaces = c.solving.surfaces = None
        return (f"contacts: no link's collision geometry could be read ({e}); every contact "
                "is checked by max_contact_link_distance from its link's frame only")
    for c, s in zip(ctrls, surfaces):
        c.store.surfaces = c.solving.surfaces = s
    hand = ctrls[0].setup.hand
    bare = surfaces[0].bare(hand)
    if not bare:
        return ''
    shown = ', '.join(bare[:8]) + (f' and {len(bare) - 8} more' if len(bare) > 8 else '')
    return (f'contacts: {len(bare)} link(s) a joint moves have no collision geometry in the '
            f'URDF ({shown}): a contact on one is checked by max_contact_link_distance from '
            'its frame, not on its surface')
