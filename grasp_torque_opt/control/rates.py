# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The rate rule: flapping inputs cannot chatter the motors (docs/node.md, "The rate rule").

An input that flaps between two values (true and false contacts at 500 Hz gave 1,716
torque sign flips in 3 s, steps of 0.24 N m; gravity +x/-x at 1 kHz, steps of 0.21
N m) made every command a step. Two bounds:

- the command: a certified command farther from the command in force than
  ``max_torque_rate`` allows since that command is published as a step of at most that
  rate towards it (:func:`slewed`); each joint's torque changes at most that fast,
  whatever the inputs do (the planar hand's torque moved 0.09 N m for a 0.05 rad turn of
  its contact normals: no input bound gives a torque bound). The step is taken along
  the straight line, the same fraction of every joint's change, so that it is the
  convex combination of two commands whose contact wrenches are known: the same
  combination of those wrenches is the step's, inside the exact cone when both ends
  are (:func:`step_wrenches`), across a change of the contact set too (a contact that
  leaves fades out, one that comes fades in); a step is at most the rate times
  ``command_period`` whatever the gap, and one from zero torques adds g(q) whole;
- gravity: the gravity in use moves towards each accepted message at most
  ``max_gravity_rate`` times the time since the one in use was taken, turning
  (:func:`turned_towards`: its norm stays within the bounds both ends meet);
  the first message, and one after the gravity in use went stale, are taken whole.
"""

from __future__ import annotations

from grasp_torque_opt.native.loader import fast_cycle
import numpy as np


def turned_towards(old: np.ndarray, new: np.ndarray, step: float) -> np.ndarray:
    """
    Move a vector towards another by at most ``step``, turning it rather than cutting across.

    The direction turns towards ``new``'s by at most ``step / |old|`` radians (an arc of at
    most ``step``), and the norm changes by at most ``step``: so the norm stays between
    the two norms, within the same bounds as both (a straight cut from +x to -x gravity
    passes through zero gravity). A half turn goes round any axis at right angles.

    Args:
        old: the vector in use, shape (3,).
        new: the vector received, shape (3,).
        step: the largest change [the vectors' unit].
    """
    n_old, n_new = float(np.linalg.norm(old)), float(np.linalg.norm(new))
    if n_old < 1e-12 or n_new < 1e-12:  # zero gravity allowed: no direction to turn
        delta = new - old
        d = float(np.linalg.norm(delta))
        return new.copy() if d <= step else old + delta * (step / d)
    u, v = old / n_old, new / n_new
    cos = float(np.clip(u @ v, -1.0, 1.0))
    angle = float(np.arccos(cos))
    turn = min(angle, step / n_old)
    if turn < angle:
        w = v - cos * u
        if float(np.linalg.norm(w)) < 1e-12:  # a half turn: any axis at right angles
            w = np.cross(u, [1.0, 0.0, 0.0] if abs(u[0]) < 0.9 else [0.0, 1.0, 0.0])
        w = w / np.linalg.norm(w)
        v = np.cos(turn) * u + np.sin(turn) * w
    return v * (n_old + float(np.clip(n_new - n_old, -step, step)))


def within_step(in_force: np.ndarray, target: np.ndarray, step: float) -> bool:
    """
    Tell whether no joint of ``target`` is farther than ``step`` from ``in_force``.

    Then :func:`slewed` gives None whatever the shift (``shift + delta`` is this change).
    False for NaN, and for arrays of two shapes (:func:`slewed` refuses those). Every
    cycle asks it: in one compiled call where the compiled module is built (a fifth of
    the numpy form's time), else :func:`within_step_numpy`; the same answer.
    """
    if fast_cycle is not None and in_force.shape == target.shape:
        return fast_cycle.within_step(in_force, target, step)
    return within_step_numpy(in_force, target, step)


def within_step_numpy(in_force: np.ndarray, target: np.ndarray, step: float) -> bool:
    """Give :func:`within_step` in numpy."""
    if in_force.shape != target.shape:
        return False
    return not target.size or bool(np.abs(target - in_force).max() <= step)


def slewed(in_force: np.ndarray, target: np.ndarray, step: float,
           limits: np.ndarray, shift: np.ndarray | None = None
           ) -> tuple[np.ndarray, float] | None:
    """
    Return the command that moves from ``in_force`` towards ``target`` by at most ``step``.

    The step is the same fraction ``s`` of every joint's change (a point of the segment
    from ``in_force`` to ``target``), the largest with no joint moving more than
    ``step``: a convex combination of the two commands, so within ``limits`` when both
    are, and its contact wrenches are the same combination of theirs.

    Args:
        in_force: the command the effort controller holds [N m], shape (m,).
        target: the certified command [N m], shape (m,).
        step: the largest change of any joint's torque [N m].
        limits: the torque limits [N m], shape (m,).
        shift: the change of g(q) since ``in_force`` [N m], at most ``step`` a joint,
            added whole (None: none). The step then starts at ``in_force + shift`` (the
            contact torques in force under today's g(q)) and goes towards ``target`` by
            the largest ``s`` with no joint moving from ``in_force`` by more than
            ``step``.

    Returns:
        The step and its fraction ``s`` in [0, 1), or None when ``target`` is within
        ``step`` already or ``in_force`` is not within ``limits`` (lowered since): then
        the certified command is published whole.
    """
    if in_force.shape != target.shape or within_step(in_force, target, step) \
            or not (np.abs(in_force) <= limits).all():
        return None
    if shift is not None:
        return _shifted(in_force + shift, shift, target, step, limits)
    delta = target - in_force
    largest = float(np.abs(delta).max()) if delta.size else 0.0
    if largest <= step:
        return None
    s = max(step, 0.0) / largest
    return in_force + s * delta, s


def _shifted(start: np.ndarray, shift: np.ndarray, target: np.ndarray, step: float,
             limits: np.ndarray) -> tuple[np.ndarray, float] | None:
    """:func:`slewed` from ``start`` (``in_force + shift``): |shift + s delta| <= step."""
    if not (np.abs(start) <= limits).all():
        return None
    delta = target - start
    bound = np.maximum(max(step, 0.0), np.abs(shift))  # (|shift| <= step: the caller's)
    moving = delta != 0.0
    if not moving.any():
        return None
    # Per joint the largest s with |shift + s delta| <= bound (0 is always within).
    ends = (np.sign(delta[moving]) * bound[moving] - shift[moving]) / delta[moving]
    s = float(min(ends.min(), 1.0))
    if s >= 1.0:
        return None
    return start + s * delta, max(s, 0.0)


def step_wrenches(in_force: np.ndarray | None, in_links: tuple[str, ...] | None,
                  target: np.ndarray | None, links: tuple[str, ...] | None, s: float
                  ) -> tuple[np.ndarray, tuple[str, ...], np.ndarray] | None:
    """
    Give the contact wrenches of a step: ``(1 - s) in_force + s target``, contact by contact.

    A contact of both commands (the same link) takes the combination of its two wrenches;
    one only in the certified command's set fades in (``s`` times its wrench), one only in
    the command in force's fades out (``1 - s`` times its): every step of a contact-set
    change is a combination of two commands whose wrenches are known, each contact's
    inside the exact cone when both ends' are (zero is in it).

    Args:
        in_force: the contact wrenches of the command in force, shape (k, 4) [N, N m],
            shape (0, 4) for zero torques (a step from them is ``s`` times the certified
            command's wrenches), or None (not known).
        in_links: their links (None: not known).
        target: the certified command's, shape (p, 4).
        links: their links.
        s: the step's fraction.

    Returns:
        (the wrenches of ``links``' contacts, shape (p, 4); the links fading out; their
        wrenches, shape (k', 4)), or None when they are not known or a set names a link
        twice (the certified command is then published whole).
    """
    none = np.zeros((0, 4))
    if in_force is None or target is None:
        return None
    if in_force.size == 0:
        return s * target, (), none
    if in_links is None or links is None or len(set(in_links)) != len(in_links) \
            or len(set(links)) != len(links) or in_force.shape != (len(in_links), 4) \
            or target.shape != (len(links), 4):
        return None
    index = {link: i for i, link in enumerate(in_links)}
    wrenches = s * target
    for i, link in enumerate(links):
        if link in index:
            wrenches[i] += (1.0 - s) * in_force[index[link]]
    gone = tuple(link for link in in_links if link not in set(links))
    faded = (1.0 - s) * in_force[[index[link] for link in gone]] if gone else none
    return wrenches, gone, faded
