// Copyright 2026 grasp_torque_opt developers
//
// Use of this source code is governed by a BSD-style
// license that can be found in the LICENSE file or at
// https://developers.google.com/open-source/licenses/bsd
//
// SPDX-License-Identifier: BSD-3-Clause

// grasp_torque_opt.control._fast_cycle_avx2: the compiled cycle (fast_cycle.hpp), built
// by setup.py with -mavx2 -mfma; a file of its own, so that its object file is its own.

#define FAST_CYCLE_MODULE _fast_cycle_avx2
#include "fast_cycle.hpp"
