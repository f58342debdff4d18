# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
A grasp for a new hand: close each finger on the object until its collision geometry touches.

The *sweep IK* (docs/hands.md, "Making a grasp"): each finger moves along a straight
path in joint space, q_f(s) = s q_f_closed for s from 0 to 1 (``q_f_closed`` within the
URDF limits, so every pose on the way is too), until MuJoCo finds its contact link's
collision geometry touching the object; s is then bisected until the touch is within
:data:`TOUCH` of the surface. A link that is not a planned contact touching the object
first is an error: the grasp would not be the planned one. The result is the scenario
with the joint positions and, per finger, the contact point where MuJoCo found the
touch, in the link's frame; the normals are left to their default (towards
``grasp.object_origin``, the inward normal of a ball about its centre).
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any
import warnings

from grasp_torque_opt.core.exceptions import GeometryWarning, InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.scenario import parse_scenario
from grasp_torque_opt.sim.model import build_model, SimModel
import mujoco
import numpy as np
import pinocchio as pin

#: Deepest penetration accepted at the touch [m].
TOUCH = 2e-5
#: Steps of the sweep from s = 0 to 1, before the bisection.
STEPS = 400


def _touching(sim: SimModel, data: mujoco.MjData) -> list[tuple[str, np.ndarray, float]]:
    """(link, point in MuJoCo's world, distance) of every contact with the object."""
    m, out = sim.model, []
    for i in range(data.ncon):
        c = data.contact[i]
        b1, b2 = m.geom_bodyid[c.geom1], m.geom_bodyid[c.geom2]
        if sim.object_body in (b1, b2):
            other = b2 if b1 == sim.object_body else b1
            out.append((m.body(other).name, c.pos.copy(), float(c.dist)))
    return out


def sweep_grasp(doc: dict[str, Any], base_dir: Path,
                closed: dict[str, dict[str, float]]) -> dict[str, Any]:
    """
    Close the fingers of a scenario document on its object.

    Args:
        doc: a scenario document with ``object``, ``gravity`` and one contact per finger
            (its link; the positions are found here).
        base_dir: the folder its relative paths are relative to.
        closed: per contact link, its finger's joints and their closed positions [rad].

    Returns:
        The document with ``grasp.joint_positions`` and the contacts' positions set.

    Raises:
        InputError: a link other than the planned contacts touches the object first, or
            a finger reaches its closed pose without touching (field ``grasp.contacts``).
    """
    doc = copy.deepcopy(doc)
    scratch = copy.deepcopy(doc)
    for contact in scratch['grasp']['contacts']:  # a link's origin until its touch is found
        contact.setdefault('position', [0.0, 0.0, 0.0])
    scenario = parse_scenario(scratch, base_dir)
    with warnings.catch_warnings():  # the placeholders are off the object, knowingly
        warnings.simplefilter('ignore', GeometryWarning)
        setup = GraspSetup.from_scenario(scenario)
    sim = build_model(scenario, setup=setup)
    data = mujoco.MjData(sim.model)
    joints = list(sim.joints)
    q = data.qpos[sim.qpos_adr].copy()
    fingers = {link: ([joints.index(j) for j in js], np.array(list(js.values())))
               for link, js in closed.items()}

    def pose(link_s: dict[str, float]) -> list[tuple[str, np.ndarray, float]]:
        for link, s in link_s.items():
            idx, end = fingers[link]
            q[idx] = s * end
        data.qpos[sim.qpos_adr] = q
        for follower, target, k, b in sim.followers:  # coupled joints follow their actuators
            data.qpos[follower] = k * data.qpos[target] + b
        mujoco.mj_forward(sim.model, data)
        return _touching(sim, data)

    points = _touch_points(pose, fingers, _first_touches(pose, fingers))
    model = setup.hand.model
    full = setup.q.copy()
    full[setup.hand.idx_q] = q
    pin.framesForwardKinematics(model, setup.hand.data, setup.hand.complete(full))
    positions = {n: round(float(v), 4) for n, v in zip(joints, q)}
    doc['grasp']['joint_positions'] = {**doc['grasp'].get('joint_positions', {}), **positions}
    for contact in doc['grasp']['contacts']:
        oMl = setup.hand.data.oMf[model.getFrameId(contact['link'])]
        contact['position'] = [round(float(x), 5) for x in oMl.actInv(points[contact['link']])]
    return doc


def _first_touches(pose, fingers: dict) -> dict[str, float]:
    """Sweep every finger from s = 0 to 1: the s at which each contact link first touches."""
    hit: dict[str, float] = {}
    for s in np.linspace(0.0, 1.0, STEPS + 1):
        touches = pose({link: s for link in fingers if link not in hit})
        for link, _, _ in touches:
            if link not in fingers:
                raise InputError('grasp.contacts', f"link '{link}' touches the object before "
                                 f'the planned contacts (s = {s:.3f})')
            hit.setdefault(link, s)
        if len(hit) == len(fingers):
            break
    missing = sorted(set(fingers) - set(hit))
    if missing:
        raise InputError('grasp.contacts', f"{', '.join(missing)}: closed without touching")
    return hit


def _touch_points(pose, fingers: dict, hit: dict[str, float]) -> dict[str, np.ndarray]:
    """Bisect each finger's s to a touch within TOUCH; its point in MuJoCo's world [m]."""
    s_of = dict.fromkeys(fingers, 0.0)
    points = {}
    for link, s_hit in hit.items():
        lo, hi = s_hit - 1.0 / STEPS, s_hit
        for _ in range(40):
            s_of[link] = 0.5 * (lo + hi)
            mine = [t for t in pose(s_of) if t[0] == link]
            if mine and min(t[2] for t in mine) < -TOUCH:
                hi = s_of[link]
            else:
                if mine:
                    points[link] = min(mine, key=lambda t: t[2])[1]
                    break
                lo = s_of[link]
        if link not in points:  # not within TOUCH in 40 halvings: the first touch found
            s_of[link] = hi
            points[link] = min((t for t in pose(s_of) if t[0] == link), key=lambda t: t[2])[1]
        pose({link: s_of[link]})
    return points
