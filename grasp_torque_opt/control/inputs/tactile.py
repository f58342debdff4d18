# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The fingertips' normal forces (``tactile.source``): an array mapped to links, or a wrench per link.

Two forms, one state (:attr:`Inputs.tactile <grasp_torque_opt.control.inputs.store.Inputs>`:
link -> :class:`Touch`):

- ``array``: std_msgs/Float32MultiArray on ``tactile``, entry i on link
  ``tactile.links[i]`` ('' for an entry not used), times ``tactile.scale`` [N]. The
  Allegro V5 Sense publishes 16 values: palm, thumb (root, middle, tip), then index,
  middle and ring (root, second, third, tip): its fingertips are entries 3, 7, 11, 15
  (docs/node.md, "Tactile input").
- ``wrench``: geometry_msgs/WrenchStamped on ``tactile_wrench``, one link per message
  (``header.frame_id``), the force the link applies to the object in the link's axes
  (as the node's own ``~/contact_wrench``); its normal force is taken along the planned
  contact's inward normal when it is used (:mod:`grasp_torque_opt.control.tactile`).

A message is checked whole (length, links, finite, not pulling, not oversized) and a
rejected one changes nothing. Readings are never part of a command's certificate: they
are compared with the planned contact forces after each cycle.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from grasp_torque_opt.core.exceptions import InputError
import numpy as np

#: The sources of ``tactile.source`` (none: not subscribed).
SOURCES = ('none', 'array', 'wrench')


@dataclass(frozen=True)
class Touch:
    """
    One link's latest accepted reading.

    Attributes:
        time: its receipt time (monotonic) [s].
        normal: the array form's normal force [N] (None in the wrench form).
        force: the wrench form's force on the object, the link's axes [N], shape (3,)
            (None in the array form).
    """

    time: float
    normal: float | None = None
    force: np.ndarray | None = None


@dataclass(frozen=True)
class TactileArrayReading:
    """A tactile array as plain data: ``data``, one value per entry of ``tactile.links``."""

    data: Any


@dataclass(frozen=True)
class TactileWrenchReading:
    """
    One link's tactile wrench as plain data.

    Attributes:
        frame: ``header.frame_id``: the link.
        force: the force the link applies to the object, its axes [N], shape (3,).
        torque: [N m], shape (3,) (checked finite, not used).
    """

    frame: str
    force: Any
    torque: Any


def mapped_links(config) -> tuple[str, ...]:
    """Return ``tactile.links`` as given ('' entries included; unset: none)."""
    return tuple(config.tactile_links or ())


def _link_known(store, field: str, link: str) -> None:
    """Refuse a link that is not a frame of the hand's model (an unknown link)."""
    if not store.setup.hand.model.existFrame(link):
        raise InputError(field, f"'{link[:64]}' is not a link of the hand")


def _newtons(field: str, value: float, config) -> float:
    """Check one normal force [N]: finite, not pulling, not oversized; give it (>= 0)."""
    if not np.isfinite(value):
        raise InputError(field, f'is not finite ({value})')
    if value < -config.tactile_negative_tolerance:
        raise InputError(field, f'is {value:.4g} N, below -tactile.negative_tolerance '
                         f'({config.tactile_negative_tolerance} N): a sensor cannot pull')
    if value > config.tactile_max_force:
        raise InputError(field, f'is {value:.4g} N, above tactile.max_force '
                         f'({config.tactile_max_force} N)')
    return max(value, 0.0)


class _TactileBase:
    """What both forms share: the subscription switch, the timeout, the freshness rule."""

    qos = 'sensor_data'
    counted = False
    enabled = 'tactile.source'
    timeout = 'tactile.timeout, tactile.required'
    form = ''

    @property
    def enabled_when(self) -> str:
        """Return the value of ``tactile.source`` that subscribes this form."""
        return self.form

    def keep(self, store, value: dict[str, Touch], now: float) -> dict[str, Any]:
        """Keep the readings: the array's replace all, a wrench's replaces its link's."""
        old = store.inputs.tactile if self.form == 'wrench' else None
        return {'tactile': {**(old or {}), **value}, 'tactile_time': now}

    def stamp_timeout(self, config) -> float:
        """Return tactile.timeout."""
        return config.tactile_timeout

    def stale(self, inputs, config, now: float) -> str:
        """
        With ``tactile.required``: say which mapped link has no fresh reading.

        Without it (the default) never stale: an old reading is not used, said on
        /diagnostics (``tactile.stale``), and the node commands on.
        """
        if config.tactile_source != self.form or not config.tactile_required:
            return ''
        got = inputs.tactile or {}
        links = [x for x in mapped_links(config) if x] or list(got)
        if not links:
            return f'{self.name} stale (none received; tactile.required)'
        for link in links:
            touch = got.get(link)
            if touch is None:
                return f'{self.name} stale ({link}: none received; tactile.required)'
            if now - touch.time > config.tactile_timeout:
                return (f'{self.name} stale ({link}: {now - touch.time:.3f} s > '
                        f'tactile.timeout {config.tactile_timeout} s; tactile.required)')
        return ''


class TactileArray(_TactileBase):
    """The tactile input, its array form (:class:`~.base.NodeInput`)."""

    name = 'tactile'
    message = 'std_msgs/msg/Float32MultiArray'
    form = 'array'

    def size(self, store, n: int, frame_id: str = '') -> None:
        """Refuse an array whose length is not tactile.links', unread."""
        k = len(mapped_links(store.config))
        if n != k:
            raise InputError('tactile.data', f'has {n} entries, tactile.links maps {k}')

    def check(self, store, reading: TactileArrayReading) -> dict[str, Touch]:
        """
        Check an array whole; give each mapped link's normal force.

        Raises:
            InputError: a length other than tactile.links', no entry mapped, a mapped link
                unknown to the hand, an entry not finite, below -negative_tolerance or above
                max_force (after tactile.scale).
        """
        c = store.config
        data = np.asarray(reading.data, dtype=float).ravel()
        self.size(store, data.size)
        if not any(mapped_links(c)):
            raise InputError('tactile.links', 'maps no entry to a link')
        out = {}
        for i, (link, raw) in enumerate(zip(mapped_links(c), data)):
            value = _newtons(f'tactile.data[{i}]', float(raw) * c.tactile_scale, c)
            if link:
                _link_known(store, f'tactile.links[{i}]', link)
                out[link] = Touch(store.now, normal=value)
        return out


class TactileWrench(_TactileBase):
    """The tactile input, its wrench form (:class:`~.base.NodeInput`)."""

    name = 'tactile_wrench'
    message = 'geometry_msgs/msg/WrenchStamped'
    form = 'wrench'

    def check(self, store, reading: TactileWrenchReading) -> dict[str, Touch]:
        """
        Check one link's wrench; give its force.

        Raises:
            InputError: an empty or unknown frame_id, one not in tactile.links (when that is
                set), a force or torque not finite, a force above max_force.
        """
        c, link = store.config, reading.frame
        field = 'tactile_wrench.header.frame_id'
        if not link:
            raise InputError(field, 'is empty: name the link the sensor is on')
        _link_known(store, field, link)
        mapped = [x for x in mapped_links(c) if x]
        if mapped and link not in mapped:
            raise InputError(field, f"'{link[:64]}' is not in tactile.links (unmapped)")
        force = np.asarray(reading.force, dtype=float)
        torque = np.asarray(reading.torque, dtype=float)
        for name, v in (('force', force), ('torque', torque)):
            if v.shape != (3,) or not np.all(np.isfinite(v)):
                raise InputError(f'tactile_wrench.wrench.{name}', 'is not finite')
        norm = float(np.linalg.norm(force))
        if norm > c.tactile_max_force:
            raise InputError('tactile_wrench.wrench.force', f'is {norm:.4g} N, above '
                             f'tactile.max_force ({c.tactile_max_force} N)')
        return {link: Touch(store.now, force=force)}


TACTILE = TactileArray()
TACTILE_WRENCH = TactileWrench()
