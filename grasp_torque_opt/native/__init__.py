# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The compiled extension (``src/``) and its loader, at the backends' level.

``setup.py`` builds ``src/fast_cycle.cpp`` into ``grasp_torque_opt.native._fast_cycle``
(and on x86-64 ``src/fast_cycle_avx2.cpp`` into ``_fast_cycle_avx2``), with pybind11,
Eigen and ProxSuite's C++ headers; :mod:`~grasp_torque_opt.native.loader` picks the one
this CPU runs. The node's compiled cycle (:mod:`grasp_torque_opt.control.compiled`) and
the batch scorer's stages (:mod:`grasp_torque_opt.methods.batch`) take it from there.
"""
