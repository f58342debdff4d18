# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The numerical core: no ROS, no solver (numpy, SciPy's linear algebra and Pinocchio only).

Scenario files, the hand model, contact frames, the grasp matrix G and hand
Jacobian J, the friction polygons, the tau-QP's data (a plain dataclass), the
certificate, the :class:`~grasp_torque_opt.core.solution.Solution` type and its
JSON form. A test imports it with ROS and every solver blocked.
"""
