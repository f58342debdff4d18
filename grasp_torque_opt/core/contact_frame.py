# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Contact frames by the pinned rule (docs/design.md section 1).

Contact frame i: origin at the contact point p_i, z_i the inward unit normal
(from the finger into the object), x_i = normalize(a x z_i) with a the base
axis with the smallest |a . z_i| (the first on a tie), y_i = z_i x x_i; or
x_i from a given tangent projected on the tangent plane.
"""

from __future__ import annotations

import math

from grasp_torque_opt.core.exceptions import InputError
import numpy as np


def contact_rotation(normal: np.ndarray, tangent: np.ndarray | None = None,
                     field: str = 'normal') -> np.ndarray:
    """
    Rotation of a contact frame in base axes.

    Args:
        normal: inward normal in base axes, shape (3,); normalized here.
        tangent: optional x axis in base axes, shape (3,); projected on the
            tangent plane and normalized.
        field: name of the input, for errors (e.g. ``grasp.contacts[0]``).

    Returns:
        R, shape (3, 3), columns x_i, y_i, z_i in base axes (base <- contact).

    Raises:
        InputError: zero or non-finite normal, or tangent parallel to the normal.
    """
    return contact_rotations(np.reshape(normal, (1, 3)), [tangent], [field])[0]


def contact_rotations(normals: np.ndarray, tangents: list[np.ndarray | None],
                      fields: list[str]) -> np.ndarray:
    """
    Rotations of p contact frames at once (the rule of :func:`contact_rotation`).

    Plain float arithmetic per contact: for a handful of contacts it costs a
    sixth of the same rule written with numpy array operations.

    Args:
        normals: inward normals in base axes, shape (p, 3).
        tangents: per contact, an x axis in base axes or None.
        fields: per contact, its name for errors.

    Returns:
        Shape (p, 3, 3); [i] has columns x_i, y_i, z_i.

    Raises:
        InputError: naming the first contact with a zero or non-finite normal,
            or a tangent parallel to its normal.
    """
    out = []
    for (nx, ny, nz), t, field in zip(np.asarray(normals, dtype=float).tolist(), tangents,
                                      fields):
        norm = math.sqrt(nx * nx + ny * ny + nz * nz)
        if not math.isfinite(norm) or norm < 1e-9:
            raise InputError(f'{field}.normal', 'must be finite and not zero')
        zx, zy, zz = nx / norm, ny / norm, nz / norm
        if t is None:
            # x = a x z, a the base axis least aligned with z (the first on a tie).
            ax, ay, az = abs(zx), abs(zy), abs(zz)
            if ax <= ay and ax <= az:
                xx, xy, xz = 0.0, -zz, zy
            elif ay <= az:
                xx, xy, xz = zz, 0.0, -zx
            else:
                xx, xy, xz = -zy, zx, 0.0
        else:
            tx, ty, tz = (float(v) for v in np.asarray(t, dtype=float).reshape(3))
            tn = math.sqrt(tx * tx + ty * ty + tz * tz)
            if not math.isfinite(tn) or tn < 1e-9:
                raise InputError(f'{field}.tangent', 'must be finite and not zero')
            tx, ty, tz = tx / tn, ty / tn, tz / tn
            d = tx * zx + ty * zy + tz * zz
            xx, xy, xz = tx - d * zx, ty - d * zy, tz - d * zz
            if math.sqrt(xx * xx + xy * xy + xz * xz) < 1e-6:
                raise InputError(f'{field}.tangent', 'is parallel to the normal')
        k = 1.0 / math.sqrt(xx * xx + xy * xy + xz * xz)
        xx, xy, xz = xx * k, xy * k, xz * k
        yx, yy, yz = zy * xz - zz * xy, zz * xx - zx * xz, zx * xy - zy * xx
        out.append(((xx, yx, zx), (xy, yy, zy), (xz, yz, zz)))
    return np.array(out, dtype=float).reshape(-1, 3, 3)
