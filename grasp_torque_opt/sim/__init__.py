# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The hand in MuJoCo: a physics check of the certified torques (docs/simulation.md).

Optional: needs the ``sim`` extra (``pip install -e '.[sim]'``, which
``scripts/setup.sh`` installs). Nothing outside this family and
:mod:`grasp_torque_opt.ros.sim_driver` imports MuJoCo. Same rank as
:mod:`~grasp_torque_opt.control`: it uses the core and :func:`~grasp_torque_opt.methods.solve`.

- :mod:`~grasp_torque_opt.sim.model`: the MuJoCo model of a scenario (hand URDF plus object);
- :mod:`~grasp_torque_opt.sim.simulator`: stepping with a joint impedance, pinning
  the object while the fingers settle, contact and object measurements;
- :mod:`~grasp_torque_opt.sim.hold`: a hold episode of the certified torques and its report;
- :mod:`~grasp_torque_opt.sim.render`: one offscreen picture with contact force arrows;
- :mod:`~grasp_torque_opt.sim.base_motion`: the base's acceleration as apparent gravity,
  the palm IMU;
- :mod:`~grasp_torque_opt.sim.rig`: the hand on a moving base with a noisy encoder,
  reporting the torques it applies;
- :mod:`~grasp_torque_opt.sim.episode`: one episode on the rig for any controller;
- :mod:`~grasp_torque_opt.sim.baselines`: a grasp preset and a position-controlled
  squeeze, the controllers hands ship with.
"""

import os

# Offscreen rendering needs no display: EGL (Mesa's software EGL will do). MuJoCo reads
# this when it is first imported, so it is set before any module here imports it.
os.environ.setdefault('MUJOCO_GL', 'egl')
