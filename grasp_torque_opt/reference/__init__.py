# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Reference methods and independent checks, beside the product's tau-QP.

The contact-force QP, the exact cone as an SOCP and as an NLP (Clarabel, SciPy
SLSQP), and the HiGHS LP that confirms an infeasible verdict. They build on the
core only; :func:`grasp_torque_opt.methods.solve` dispatches to them.
"""
