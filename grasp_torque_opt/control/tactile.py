# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
What the fingertips' measured normal forces say about the planned contacts.

After each certified cycle the command's contact wrenches (f_x, f_y, f_n, m_z in each
contact frame) are compared with the tactile readings of their links
(:mod:`grasp_torque_opt.control.inputs.tactile`), fresh within ``tactile.timeout``:

- **measured friction usage** u_i = ||f_t,i|| / (mu1 m_i), the planned tangential force
  over what friction can give at the measured normal force m_i: 1 on the cone's edge. It
  is the certificate's usage with the measured normal force in place of the planned
  one: a contact pressed less than planned uses more of its cone. NaN where no fresh
  reading, inf where the measured force is zero and the plan asks for a tangential one;
- **contact loss**: a planned contact whose measured normal force is below
  ``tactile.loss_ratio`` times the planned one (zero included): slipping, or off the
  object.

:func:`tactile_report` is the pure function; the controller keeps its last
:class:`TactileReport` (``TorqueController.tactile``): its ``usage`` is the measured
friction usage per contact, in the order of the command's contacts (``links``), that a
squeeze following friction can take as its measurement.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class TactileReport:
    """
    The planned contacts against the tactile readings, one entry per planned contact.

    Attributes:
        links: the contacts' links, in the command's order.
        planned: planned normal forces [N], shape (p,).
        measured: measured normal forces [N], shape (p,): NaN where the link has no
            fresh reading (or, in the wrench form, one pulling beyond the tolerance).
        usage: measured friction usage ||f_t|| / (mu1 measured) [-], shape (p,): NaN
            without a measurement, inf at a zero measured force under a tangential plan.
        lost: indices of the contacts measured below ``loss_ratio`` times planned.
        stale: indices of the contacts without a fresh reading.
        pulling: indices whose wrench form reads a normal force below the tolerance.
        wrenches: the command's contact wrenches compared, shape (p, 4) (to compare again
            later, :meth:`at`).
        normals: the contacts' inward normals in their links' axes, shape (p, 3), or None.
    """

    def at(self, readings: Mapping | None, now: float, config, mu1: float) -> TactileReport:
        """Compare the same command with the readings at ``now`` (their ages then)."""
        return tactile_report(self.wrenches, self.links, readings, self.normals, now,
                              config, mu1)

    links: tuple[str, ...]
    planned: np.ndarray
    measured: np.ndarray
    usage: np.ndarray
    lost: tuple[int, ...]
    stale: tuple[int, ...]
    pulling: tuple[int, ...] = ()
    wrenches: np.ndarray | None = None
    normals: np.ndarray | None = None


def measured_usage(tangential: np.ndarray, measured: np.ndarray, mu1: float) -> np.ndarray:
    """
    Return ||f_t|| / (mu1 m) per contact: the planned tangential force over the measured cone.

    Args:
        tangential: the planned tangential force's norms [N], shape (p,).
        measured: the measured normal forces [N], shape (p,) (NaN: no measurement).
        mu1: the tangential friction coefficient [-].

    Returns:
        Shape (p,): NaN where ``measured`` is NaN; 0 where nothing tangential is planned;
        inf where the measured force is zero under a tangential plan.
    """
    t = np.asarray(tangential, dtype=float)
    m = np.asarray(measured, dtype=float)
    out = np.full(t.shape, np.nan)
    known = np.isfinite(m)
    with np.errstate(divide='ignore', invalid='ignore'):
        out[known] = np.where(t[known] == 0.0, 0.0, t[known] / (mu1 * m[known]))
    return out


def lost_contacts(planned: np.ndarray, measured: np.ndarray, ratio: float) -> tuple[int, ...]:
    """Return the contacts measured below ``ratio`` times their planned normal force."""
    p, m = np.asarray(planned, dtype=float), np.asarray(measured, dtype=float)
    return tuple(int(i) for i in np.flatnonzero(np.isfinite(m) & (m < ratio * p)))


def tactile_report(wrenches: np.ndarray, links: Sequence[str], readings: Mapping | None,
                   normals: np.ndarray | None, now: float, config, mu1: float
                   ) -> TactileReport:
    """
    Compare a command's contact wrenches with the tactile readings.

    Args:
        wrenches: the command's contact wrenches, shape (p, 4): f_x, f_y, f_n, m_z [N, N m].
        links: the contacts' links, shape (p,).
        readings: link -> :class:`~grasp_torque_opt.control.inputs.tactile.Touch` (None:
            none received).
        normals: the contacts' inward normals in their links' axes, shape (p, 3) (the
            wrench form's force is projected on them); None: only array readings are read.
        now: the time the readings are aged at (monotonic) [s].
        config: ``tactile_timeout``, ``tactile_loss_ratio``, ``tactile_negative_tolerance``.
        mu1: tangential friction [-].
    """
    w = np.asarray(wrenches, dtype=float).reshape(len(links), -1)
    measured = np.full(len(links), np.nan)
    stale, pulling = [], []
    for i, link in enumerate(links):
        touch = (readings or {}).get(link)
        if touch is None or now - touch.time > config.tactile_timeout:
            stale.append(i)
            continue
        if touch.normal is not None:
            measured[i] = touch.normal
            continue
        if normals is None:
            stale.append(i)
            continue
        value = float(np.asarray(touch.force) @ normals[i])
        if value < -config.tactile_negative_tolerance:
            pulling.append(i)
            continue
        measured[i] = max(value, 0.0)
    planned = w[:, 2].copy()
    usage = measured_usage(np.hypot(w[:, 0], w[:, 1]), measured, mu1)
    return TactileReport(tuple(links), planned, measured, usage,
                         lost_contacts(planned, measured, config.tactile_loss_ratio),
                         tuple(stale), tuple(pulling), w, normals)
