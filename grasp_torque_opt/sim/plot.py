# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The plot beside the picture: the object's drift and the hand's effort over the hold.

One line per run (the node over ROS, the baseline in the same rig), drift in plain
millimetres on top with the held limit (drawn when the drifts come within half of it;
otherwise the axis ends above the largest drift, so that a held run's hundredths of a
millimetre show), the RMS joint torque below. The labels are the caller's, each term
explained in it. matplotlib draws it (the Agg backend: no display needed).
"""

from __future__ import annotations

from pathlib import Path
import textwrap

import numpy as np

#: What the plot shows, for the line that names it.
PLOT_CAPTION = 'drift and effort over time, the node beside the baseline'


def plot_runs(path: str | Path, runs: dict[str, list[tuple[float, float, float]]],
              title: str, drift_limit_mm: float) -> Path:
    """
    Write the drift and effort of some runs over time to a PNG.

    Args:
        path: where to write it.
        runs: label -> rows of (time since release [s], drift [m], RMS torque [N m]).
        title: the plot's title (the disturbance).
        drift_limit_mm: the held limit, drawn as a dashed line [mm].

    Returns:
        The path written.

    Raises:
        OSError: the file could not be written.
    """
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.0, 6.2), sharex=True,
                                      constrained_layout=True)
    for label, rows in runs.items():
        if not rows:
            continue
        a = np.asarray(rows, dtype=float)
        top.plot(a[:, 0], 1e3 * a[:, 1], label=textwrap.fill(label, 95))
        bottom.plot(a[:, 0], a[:, 2])
    top.axhline(drift_limit_mm, color='grey', linestyle='--', linewidth=1.0,
                label=f'held limit {drift_limit_mm:g} mm (off the axis when far above)')
    top.set_ylabel('drift of the object [mm]')
    # Plain millimetres: the limit drawn only when the drifts come within reach of it,
    # so that a held run's 0.01 mm still shows.
    most = max((1e3 * max(r[1] for r in rows) for rows in runs.values() if rows), default=0.0)
    top.set_ylim(0.0, 1.15 * max(most, 1e-3) if most < 0.5 * drift_limit_mm
                 else 1.15 * max(most, drift_limit_mm))
    top.set_title(title)
    fig.legend(loc='outside lower center', fontsize='small')
    bottom.set_ylabel('RMS joint torque [N m]')
    bottom.set_xlabel('time since release [s]')
    for ax in (top, bottom):
        ax.grid(True, alpha=0.3)
    out = Path(path)
    try:
        fig.savefig(out, dpi=100)
    finally:
        plt.close(fig)
    return out
