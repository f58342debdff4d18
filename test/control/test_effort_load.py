# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The effort estimate's integral: it meets a load error within reach, not an implausible one.

In the simulation the pinned ball read -1.6 N against the model's +1.47 N before release;
integrated, it put the correction at its bound at the moment of release (a 2.6 to 4.5
mm drop of a ball 3 to 5 mm off its place). Such a reading is no load of this object
alone: the correction goes back towards the model instead.
"""

from grasp_torque_opt.control.effort_load import EffortLoad, IMPLAUSIBLE
import numpy as np

WEIGHT = 1.4715  # N: 0.15 kg
MODEL = np.array([WEIGHT, 0.0, 0.0, 0.0, 0.0, 0.0])
BOUNDS = (0.5 * WEIGHT, 0.5 * WEIGHT * 0.05)
DOWN = np.array([1.0, 0.0, 0.0])


def run(est: EffortLoad, load: float, t0: float, seconds: float) -> float:
    """Feed a constant measured load along gravity at 1 kHz; return the correction's x."""
    measured = np.array([load, 0.0, 0.0, 0.0, 0.0, 0.0])
    for k in range(int(seconds * 1000)):
        est.update(measured, MODEL, t0 + 1e-3 * k, 0.01, 0.05, BOUNDS, 0.05, DOWN)
    return float(est.correction[0])


def test_a_heavier_object_is_met_within_the_bound():
    est = EffortLoad()
    assert abs(run(est, 1.3 * WEIGHT, 0.0, 1.0) - 0.3 * WEIGHT) < 1e-3
    est = EffortLoad()
    assert abs(run(est, 2.0 * WEIGHT, 0.0, 1.0) - BOUNDS[0]) < 1e-9  # clipped at the bound


def test_an_implausible_reading_is_not_integrated_and_the_correction_decays():
    pinned = -1.6  # the simulated ball before release
    assert abs(pinned - WEIGHT) > IMPLAUSIBLE * BOUNDS[0]
    est = EffortLoad()
    assert run(est, pinned, 0.0, 0.5) == 0.0  # nothing integrated
    assert est.estimate is None  # the filter starts again at a plausible reading
    est = EffortLoad()
    run(est, 1.3 * WEIGHT, 0.0, 1.0)
    assert run(est, pinned, 1.0, 0.5) < 1e-3 * WEIGHT  # back to the model's load
    assert abs(run(est, 1.3 * WEIGHT, 1.5, 1.0) - 0.3 * WEIGHT) < 1e-3  # and on again
