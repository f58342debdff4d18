# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Find and load the compiled cycle's module (src/fast_cycle.hpp) for this CPU.

The extension modules are built into this package, ``grasp_torque_opt/native/``
(``_fast_cycle``, and on x86-64 ``_fast_cycle_avx2``); the node's compiled cycle
(:mod:`grasp_torque_opt.control.compiled`) and batch scoring
(:mod:`grasp_torque_opt.methods.batch`) both take :data:`fast_cycle` from here.
"""

from __future__ import annotations

import importlib
import platform

#: The interface of src/fast_cycle.hpp this module speaks (its ``API``).
API = 11


def cpu_has_avx2() -> bool:
    """Tell whether this CPU and its OS run AVX2 and FMA code (ProxSuite's own cpuid check)."""
    if platform.machine().lower() not in ('x86_64', 'amd64'):
        return False
    try:
        from proxsuite import instructionset
        return bool(instructionset.has_AVX2() and instructionset.has_FMA()
                    and instructionset.has_OSXSAVE())
    except (ImportError, AttributeError):
        return False


def load(name: str):
    """Return the module ``name`` of the compiled cycle and '', or None and why not."""
    try:
        module = importlib.import_module(f'grasp_torque_opt.native.{name}')
    except ImportError as e:  # not built (no compiler, or a colcon build without pybind11)
        return None, f'grasp_torque_opt.native.{name} is not built ({e})'
    if getattr(module, 'API', None) != API:
        return None, (f'grasp_torque_opt.native.{name} was built from another '
                      'src/fast_cycle.hpp: run scripts/setup.sh again')
    return module, ''


#: The modules built (``_fast_cycle_avx2`` only where this CPU runs it), best first.
MODULES = ('_fast_cycle_avx2', '_fast_cycle') if cpu_has_avx2() else ('_fast_cycle',)


def _best() -> tuple[object, str]:
    """Return the best module of :data:`MODULES` that loads, or None and why none does."""
    why = ''
    for name in MODULES:
        module, reason = load(name)
        if module is not None:
            return module, ''
        why = why or reason
    return None, why


#: The compiled cycle's module in use (None: none loads) and, if none, why not.
fast_cycle, IMPORT_ERROR = _best()
