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
  its contact normals: no input bound gives a torque bound);
- gravity: the gravity in use moves towards each accepted message at most
  ``max_gravity_rate`` times the time since the one in use was taken (:func:`towards`);
  the first message, and one after the gravity in use went stale, are taken whole.
"""

from __future__ import annotations

import numpy as np


def towards(old: np.ndarray, new: np.ndarray, step: float) -> np.ndarray:
    """Move each row of ``old`` towards ``new`` by at most ``step`` (Euclidean), shape kept."""
    delta = new - old
    norm = np.linalg.norm(delta, axis=-1, keepdims=True)
    scale = np.minimum(1.0, step / np.maximum(norm, 1e-300))
    return old + delta * scale


def slewed(in_force: np.ndarray, target: np.ndarray, step: float,
           limits: np.ndarray) -> np.ndarray | None:
    """
    Return the command that moves from ``in_force`` towards ``target`` by at most ``step``.

    Args:
        in_force: the command the effort controller holds [N m], shape (m,).
        target: the certified command [N m], shape (m,).
        step: the largest change of any joint's torque [N m].
        limits: the torque limits [N m], shape (m,).

    Returns:
        The step, within ``limits`` (both ends are), or None when ``target`` is within
        ``step`` already or ``in_force`` is not within ``limits`` (lowered since): then the
        certified command is published whole.
    """
    if in_force.shape != target.shape or not (np.abs(in_force) <= limits).all():
        return None
    delta = target - in_force
    if (np.abs(delta) <= step).all():
        return None
    return in_force + np.clip(delta, -step, step)
