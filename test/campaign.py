# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The adversarial campaign's tools: generated messages, invariants and counts.

The messages are generated from their definitions, the invariants are those every
published command must meet, and the counts are printed after the run.

Strategies start from a valid message and overwrite some of its fields, each chosen
among the leaf fields that ``get_fields_and_field_types`` lists and filled with a value
of that field's type (NaN, Inf, huge, empty and oversized sequences, unknown and
duplicate names, zero and non-unit quaternions), so that the messages reach every
check and, often enough, the solver.
"""

from __future__ import annotations

import copy
import importlib

from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
import numpy as np
from rclpy.serialization import deserialize_message

#: Counts of the whole run, printed by conftest's terminal summary.
COUNTS = {'inputs': 0, 'commands': 0, 'broken': 0, 'pulling': 0, 'chattering': 0, 'late': 0}

#: Issue 33's cases (test_campaign_issue33.py): case -> its counts, printed after the run.
ISSUE33: dict[str, dict] = {}

#: Reproducible and bounded: CI sees the same examples every run.
CAMPAIGN = settings(deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.function_scoped_fixture])

#: Stands for "this sequence, 100000 entries long" (a huge message).
OVERSIZED = object()

FLOATS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.sampled_from([0.0, -0.0, np.nan, np.inf, -np.inf, 1e308, -1e308, 5e-324, 1e6, -1e6]),
    st.floats(-2.0, 2.0))


def message_class(type_name: str):
    """Return the Python class of a ROS type such as ``geometry_msgs/Pose``."""
    package, name = type_name.split('/')
    return getattr(importlib.import_module(f'{package}.msg'), name)


def leaf_fields(cls, prefix: str = '') -> list[tuple[str, str]]:
    """
    Return (dotted path, type) of every leaf field of a message class, from its definition.

    Sequences of messages are leaves (their length and content are generated whole).
    """
    out = []
    for name, typ in cls.get_fields_and_field_types().items():
        path = f'{prefix}{name}'
        if '/' in typ and not typ.startswith('sequence<'):
            out += leaf_fields(message_class(typ), path + '.')
        else:
            out.append((path, typ))
    return out


def value_of(typ: str, names: list[str], max_len: int = 12) -> st.SearchStrategy:
    """Values of a ROS field type, valid and invalid."""
    if typ in ('double', 'float'):
        return FLOATS
    if typ == 'int32':
        return st.one_of(st.integers(-2**31, 2**31 - 1), st.sampled_from([0, -1, 2**31 - 1]))
    if typ == 'uint32':
        return st.one_of(st.integers(0, 2**32 - 1), st.just(0))
    if typ == 'string':
        return st.one_of(st.sampled_from(names + ['', 'no_such_frame', 'x' * 5000]),
                         st.text(max_size=12))
    if typ.startswith('sequence<'):
        inner = typ[len('sequence<'):-1]
        item = messages_of(message_class(inner), names) if '/' in inner else \
            value_of(inner, names)
        return st.one_of(st.lists(item, max_size=max_len), st.just(OVERSIZED))
    raise NotImplementedError(typ)


def messages_of(cls, names: list[str]) -> st.SearchStrategy:
    """Messages of a class with every leaf field generated."""
    leaves = leaf_fields(cls)

    @st.composite
    def build(draw):
        msg = cls()
        for path, typ in leaves:
            set_field(msg, path, draw(value_of(typ, names)))
        return msg
    return build()


def set_field(msg, path: str, value) -> None:
    """Set a dotted field; :data:`OVERSIZED` fills a sequence with 100000 default items."""
    *parents, last = path.split('.')
    target = msg
    for p in parents:
        target = getattr(target, p)
    if value is OVERSIZED:
        item = type(getattr(target, last)[0])() if len(getattr(target, last)) else 0.0
        value = [item] * 100000
    try:
        setattr(target, last, value)
    except (AssertionError, TypeError, ValueError):
        pass  # the message type refuses it (e.g. a str in a double): never on the wire


@st.composite
def mutated(draw, valid, names: list[str], max_mutations: int = 3):
    """Draw a copy of a valid message with up to ``max_mutations`` leaf fields regenerated."""
    msg = copy.deepcopy(valid)
    leaves = leaf_fields(type(valid))
    for _ in range(draw(st.integers(0, max_mutations))):
        path, typ = draw(st.sampled_from(leaves))
        items = getattr(msg, path) if '.' not in path else None
        if typ.startswith('sequence<') and '/' in typ and items and draw(st.booleans()):
            # One field of one item, e.g. poses[1].orientation.w.
            item = items[draw(st.integers(0, len(items) - 1))]
            sub, sub_typ = draw(st.sampled_from(leaf_fields(type(item))))
            set_field(item, sub, draw(value_of(sub_typ, names)))
        else:
            set_field(msg, path, draw(value_of(typ, names)))
    return msg


def check_command(cmd, m: int, limits: np.ndarray) -> None:
    """Check the invariant on what reaches the motors: len(joints) finite values within limits."""
    COUNTS['commands'] += 1
    cmd = np.asarray(cmd, dtype=float)
    ok = cmd.shape == (m,) and bool(np.all(np.isfinite(cmd))) and \
        bool(np.all(np.abs(cmd) <= limits))
    if not ok:
        COUNTS['broken'] += 1
    assert ok, f'command broke the invariant: {cmd!r}'


def broken(why: str) -> None:
    """Count a broken invariant and fail."""
    COUNTS['broken'] += 1
    raise AssertionError(why)


class TrueGrasp:
    """
    The contact wrenches a command exerts at the TRUE grasp, computed apart from the node.

    The truth is what the scenario says: the still hand at its joint positions, holding
    its object at its contact points (normals towards the object origin, as the
    scenario's rule states), under its gravity. Nothing here comes from the package's
    grasp maps: Pinocchio, built afresh from the URDF, gives each contact link's frame
    Jacobian and g(q); the contact point's Jacobian is the link's shifted to the point
    (v_p = v + w x r); the contact's rows are the force in a frame whose z is the inward
    normal and the moment about that normal (the soft-finger model). The wrenches are
    the least-squares solution of J^T f = tau - g(q) (tau alone without gravity
    compensation): on the Allegro's four tips J^T is square and invertible (one
    contact per finger), so f is exact; on a reduced set the fingers without a contact
    are free and their torque moves them, reported as the residual, not checked.
    With contacts from geometry the truth's contacts are where the true shapes touch
    (``contacts``: coal's closest points and normals at the true configuration), since
    the scenario then states the object and the links, not the points.

    The cone is the exact soft-finger cone |f_t| / mu + |m_n| / mu_tors <= f_n: a
    command outside it at the truth slips or twists, and f_n < 0 pulls. The reference
    QP and SOCP (``grasp_torque_opt.reference``) were not used: they solve for forces
    at the package's own maps, which is what this check must not lean on.
    """

    def __init__(self, setup, urdf, gravity, tol: float = 1e-6, contacts=None):
        import pinocchio as pin

        self.pin, self.tol = pin, tol
        self.model = pin.buildModelFromUrdf(str(urdf))
        assert self.model.nq == setup.q.size
        self.model.gravity.linear = np.asarray(gravity, dtype=float)
        self.data = self.model.createData()
        self.q = setup.q.copy()
        self.idx_v = np.asarray(setup.hand.idx_v)
        self.origin = np.asarray(setup.object_origin, dtype=float)
        self.contacts = [(c.link, np.asarray(c.position, dtype=float),
                          None if c.normal is None else np.asarray(c.normal, dtype=float))
                         for c in (setup.contacts if contacts is None else contacts)]
        fr = setup.friction
        self.mu, self.mu_tors, self.f_min = fr.mu1, fr.mu2, fr.min_normal_force
        self.limits = np.asarray(setup.hand.torque_limits, dtype=float)

    def rows(self, q=None, links=None) -> tuple[np.ndarray, np.ndarray]:
        """J (4 rows a contact: f_x, f_y, f_n, m_n) and g(q) over the hand's joints, at q."""
        pin, model, data = self.pin, self.model, self.data
        q = self.q if q is None else q
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        g = pin.computeGeneralizedGravity(model, data, q)[self.idx_v]
        out = []
        for link, local, normal in self.contacts:
            if links is not None and link not in links:
                continue
            fid = model.getFrameId(link)
            oMf = data.oMf[fid]
            p = oMf.act(local)
            J = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)[:, self.idx_v]
            Jp = J[:3] - pin.skew(p - oMf.translation) @ J[3:]
            n = self.origin - p if normal is None else normal.copy()
            n /= np.linalg.norm(n)
            x = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
            x /= np.linalg.norm(x)
            R = np.column_stack((x, np.cross(n, x), n))
            out.append(np.vstack((R.T @ Jp, n @ J[3:])))
        return np.vstack(out), g

    def wrenches(self, cmd, compensated: bool, q=None, links=None):
        """Give the contact wrenches, shape (p, 4), of a command at the truth; the residual."""
        J, g = self.rows(q, links)
        tau = np.asarray(cmd, dtype=float) - (g if compensated else 0.0)
        f, *_ = np.linalg.lstsq(J.T, tau, rcond=None)
        return f.reshape(-1, 4), float(np.abs(J.T @ f - tau).max())

    def verdict(self, cmd, compensated: bool, q=None, links=None) -> str:
        """
        Say what a command is at the truth: 'ok', 'weak' (under f_min), or what forbids it.

        Forbidden: not len(joints) finite values within the limits, 'pulling' (a normal
        force below zero), 'outside the cone'.
        """
        cmd = np.asarray(cmd, dtype=float)
        if cmd.shape != self.limits.shape or not np.all(np.isfinite(cmd)):
            return 'malformed'
        if np.any(np.abs(cmd) > self.limits):
            return 'over a limit'
        w, _ = self.wrenches(cmd, compensated, q, links)
        if np.any(w[:, 2] < -self.tol):
            return 'pulling'
        if np.any(np.hypot(w[:, 0], w[:, 1]) / self.mu + np.abs(w[:, 3]) / self.mu_tors
                  > w[:, 2] + self.tol):
            return 'outside the cone'
        return 'weak' if np.any(w[:, 2] < self.f_min - self.tol) else 'ok'


def as_message(msg, kind):
    """Return what a publisher was given as a message: the node publishes bytes (wire.py)."""
    return deserialize_message(msg, kind) if isinstance(msg, bytes) else msg
