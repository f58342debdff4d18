# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Every method behind one entry point, and their comparison (the paper's Table 2).

:func:`solve` runs the kinematics, builds the problem, solves it with a backend
or a reference method, certifies the answer and decides the status.
"""

__all__ = ['METHODS', 'solve']


def __getattr__(name: str):
    """
    Give ``METHODS`` and ``solve`` from :mod:`.dispatch`, imported on first use.

    Importing a module of this package (``methods.plan``, ``methods.score``) no longer
    imports :mod:`.dispatch` and every method's solvers with it.
    """
    if name in __all__:
        from grasp_torque_opt.methods import dispatch

        return getattr(dispatch, name)
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
