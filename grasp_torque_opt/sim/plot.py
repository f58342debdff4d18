# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The plot beside the picture: the object's drift and the hand's effort over the hold.

One line per run (the node over ROS, the baseline in the same rig), drift in mm on
top with the held limit, the RMS joint torque below. matplotlib draws it (the Agg
backend: no display needed).
"""

from __future__ import annotations

from pathlib import Path

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

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.0, 5.0), sharex=True,
                                      constrained_layout=True)
    for label, rows in runs.items():
        if not rows:
            continue
        a = np.asarray(rows, dtype=float)
        top.plot(a[:, 0], 1e3 * a[:, 1], label=label)
        bottom.plot(a[:, 0], a[:, 2], label=label)
    top.axhline(drift_limit_mm, color='grey', linestyle='--', linewidth=1.0,
                label=f'held limit {drift_limit_mm:g} mm')
    top.set_ylabel('drift of the object [mm]')
    top.set_yscale('symlog', linthresh=0.1)
    top.set_ylim(bottom=0.0)
    top.set_title(title)
    top.legend(loc='upper left', fontsize='small')
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
