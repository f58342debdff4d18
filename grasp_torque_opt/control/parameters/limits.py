# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The bounds that the input checks and the parameter checks share, in one leaf module.

It imports nothing of the package, so that both the message checks
(:mod:`grasp_torque_opt.control.checks`) and the parameters' validators
(:mod:`grasp_torque_opt.control.parameters.validators`) can take them from here.
"""

#: Largest accepted norm of a gravity input [m/s^2] (about 10 g), parameter or message.
MAX_GRAVITY = 100.0

#: Each weight's range, and the largest ratio of two weights: W's condition number
#: bounds how hard the QP is (ratios of 1e12 and more kept ProxSuite at its caps).
WEIGHT_RANGE = (1e-6, 1e6)
MAX_WEIGHT_RATIO = 1e6
