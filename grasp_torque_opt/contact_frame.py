"""Contact frames by the pinned rule (DESIGN.md section 1).

Contact frame i: origin at the contact point p_i, z_i the inward unit normal
(from the finger into the object), x_i = normalize(a x z_i) with a the base
axis with the smallest |a . z_i| (the first on a tie), y_i = z_i x x_i; or
x_i from a given tangent projected on the tangent plane.
"""

from __future__ import annotations

import numpy as np

from grasp_torque_opt.exceptions import InputError


def contact_rotation(normal: np.ndarray, tangent: np.ndarray | None = None,
                     field: str = "normal") -> np.ndarray:
    """Rotation of a contact frame in base axes.

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
    z = np.asarray(normal, dtype=float)
    norm = np.linalg.norm(z)
    if not np.isfinite(norm) or norm < 1e-9:
        raise InputError(f"{field}.normal", "must be finite and not zero")
    z = z / norm
    if tangent is None:
        a = np.zeros(3)
        a[int(np.argmin(np.abs(z)))] = 1.0
        x = cross(a, z)
    else:
        t = np.asarray(tangent, dtype=float)
        tn = np.linalg.norm(t)
        if not np.isfinite(tn) or tn < 1e-9:
            raise InputError(f"{field}.tangent", "must be finite and not zero")
        t = t / tn
        x = t - (t @ z) * z
        if np.linalg.norm(x) < 1e-6:
            raise InputError(f"{field}.tangent", "is parallel to the normal")
    x = x / np.linalg.norm(x)
    return np.column_stack((x, cross(z, x), z))


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b for 3-vectors (numpy.cross costs ten times more at this size)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])
