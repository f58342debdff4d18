# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Coupled joints: URDF mimic relations and the scenario's ``hand.coupling``.

A coupled (follower) joint j follows a target joint t: q_j = k q_t + b. Followers of
followers are allowed; every chain ends at a joint that follows none, which is an
actuator (a joint of ``hand.joints``) or a locked joint. The joint velocities are then
dq = C dtheta with theta the actuators' positions, C of shape (nv, m): 1 on an actuator's
own row, the product of the multipliers along the chain on a follower's row. The
actuators' torques are u = C^T tau, and the hand Jacobian of the QP is J C
(docs/design.md section 1, coupled joints).

A URDF's mimic tag may name a joint that is not in the model (the Alex file in
example-robot-data names ``index_q1`` where the joint is ``Right_index_q1``). Such a
target is resolved by the *prefix rule*: the one joint whose name is the target's with
a prefix that the follower's name starts with, the prefix ending in one of
:data:`PREFIX_ENDS` (a namespace such as ``Right_``); none or several is an error naming
the follower and the target.
"""

from __future__ import annotations

from dataclasses import dataclass
import xml.etree.ElementTree as ET

from grasp_torque_opt.core.exceptions import cut, InputError
import numpy as np
import pinocchio as pin

#: A position that differs from its coupling by more than this is a contradiction [rad, m].
COUPLING_TOLERANCE = 1e-6
#: Characters a namespace prefix of the prefix rule ends with.
PREFIX_ENDS = '_/-.:'


@dataclass(frozen=True)
class Mimic:
    """
    One coupled joint: q_joint = multiplier * q_target + offset.

    Attributes:
        joint: the follower's name.
        target: the followed joint's name (resolved: a joint of the model).
        multiplier: k [-] (or [m/rad] between a prismatic and a revolute joint).
        offset: b [rad or m].
        source: where it was stated (``the URDF`` or ``hand.coupling.<joint>``).
    """

    joint: str
    target: str
    multiplier: float
    offset: float
    source: str


def urdf_mimics(xml: str) -> list[Mimic]:
    """
    Return the mimic tags of a URDF document, targets as written.

    Raises:
        InputError: a mimic tag without ``joint`` or with a non-numeric attribute
            (field ``hand.urdf``).
    """
    try:
        root = ET.fromstring(xml)
    except ET.ParseError as e:
        raise InputError('hand.urdf', f'cannot parse the URDF: {cut(e, 200)}') from e
    out = []
    for joint in root.iter('joint'):
        tag = joint.find('mimic')
        if tag is None or joint.get('type') == 'fixed':
            continue
        name, target = joint.get('name', ''), tag.get('joint')
        if not target:
            raise InputError('hand.urdf', f"joint '{cut(name)}': mimic tag without joint")
        try:
            k, b = float(tag.get('multiplier', 1.0)), float(tag.get('offset', 0.0))
        except ValueError as e:
            raise InputError('hand.urdf', f"joint '{cut(name)}': mimic multiplier or offset "
                             'is not a number') from e
        out.append(Mimic(name, target.strip(), k, b, 'the URDF'))
    return out


def resolve_target(joint: str, target: str, names: list[str]) -> str | None:
    """
    Return the model joint that ``target`` names for follower ``joint``, or None.

    ``target`` itself if it is a joint, else by the prefix rule (module docstring).
    """
    if target in names:
        return target
    found = [n for n in names if len(n) > len(target) and n.endswith(target)
             and n[-len(target) - 1] in PREFIX_ENDS and joint.startswith(n[:-len(target)])]
    return found[0] if len(found) == 1 else None


@dataclass(frozen=True)
class Coupling:
    """
    The coupled joints of a model, each target resolved, in dependency order.

    Attributes:
        mimics: followers; each one's target comes before it if it follows too.
    """

    mimics: tuple[Mimic, ...] = ()

    @classmethod
    def resolve(cls, model: pin.Model, mimics: list[Mimic]) -> Coupling:
        """
        Resolve targets and order the followers.

        Args:
            model: the model whose one-DoF joints are coupled.
            mimics: the relations (a later one for the same joint replaces an earlier:
                the scenario's over the URDF's).

        Raises:
            InputError: a follower or a target is not a one-DoF joint of the model
                (naming both), a joint follows itself, or the relations form a cycle.
        """
        names = [model.names[j] for j in range(1, model.njoints)
                 if model.joints[j].nq == 1 and model.joints[j].nv == 1]
        by_joint: dict[str, Mimic] = {}
        for m in mimics:
            field = 'hand.urdf' if m.source == 'the URDF' else m.source
            if m.joint not in names:
                raise InputError(field, f"coupled joint '{cut(m.joint)}' is not a one-DoF "
                                 'joint of the model')
            target = resolve_target(m.joint, m.target, names)
            if target is None:
                raise InputError(field, f"joint '{m.joint}' follows '{cut(m.target)}', which "
                                 'is not a joint of the model, and no one joint is named so '
                                 f"with a prefix of '{m.joint}' (state the coupling in "
                                 'hand.coupling)')
            if target == m.joint:
                raise InputError(field, f"joint '{m.joint}' follows itself")
            by_joint[m.joint] = Mimic(m.joint, target, m.multiplier, m.offset, m.source)
        ordered: list[Mimic] = []
        done: set[str] = set()
        for m in by_joint.values():
            chain = []
            while m is not None and m.joint not in done:
                if m in chain:
                    field = 'hand.urdf' if m.source == 'the URDF' else m.source
                    raise InputError(field, 'coupled joints follow each other in a cycle: '
                                     + ' -> '.join(c.joint for c in chain))
                chain.append(m)
                m = by_joint.get(m.target)
            for c in reversed(chain):
                ordered.append(c)
                done.add(c.joint)
        return cls(tuple(ordered))

    @property
    def followers(self) -> dict[str, Mimic]:
        """Return follower name -> its relation."""
        return {m.joint: m for m in self.mimics}

    def root(self, joint: str) -> str:
        """Return the joint at the end of ``joint``'s chain (``joint`` if it follows none)."""
        f = self.followers
        while joint in f:
            joint = f[joint].target
        return joint

    def apply(self, model: pin.Model, q: np.ndarray) -> np.ndarray:
        """Set every follower's position from its target's in ``q`` (in place); return q."""
        for m in self.mimics:
            q[_iq(model, m.joint)] = m.multiplier * q[_iq(model, m.target)] + m.offset
        return q

    def velocity_map(self, model: pin.Model, idx_v: np.ndarray) -> np.ndarray:
        """
        Return C, shape (nv, m): dq = C dtheta for the actuators at ``idx_v``.

        Rows of locked joints (and of followers of locked joints) are zero.
        """
        C = np.zeros((model.nv, len(idx_v)))
        C[idx_v, np.arange(len(idx_v))] = 1.0
        for m in self.mimics:
            C[_iv(model, m.joint)] = m.multiplier * C[_iv(model, m.target)]
        return C


def _iq(model: pin.Model, name: str) -> int:
    return model.joints[model.getJointId(name)].idx_q


def _iv(model: pin.Model, name: str) -> int:
    return model.joints[model.getJointId(name)].idx_v
