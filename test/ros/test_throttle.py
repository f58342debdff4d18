# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The joint state path's log throttle: the first line, then one a period."""

import time

from grasp_torque_opt.ros.node.throttle import Throttle


def test_the_first_line_then_none_within_the_period():
    t = Throttle(60.0)
    assert t.due()
    assert not any(t.due() for _ in range(1000))


def test_a_line_again_once_the_period_has_passed():
    t = Throttle(0.01)
    assert t.due()
    time.sleep(0.02)
    assert t.due()
    zero = Throttle(0.0)
    assert all(zero.due() for _ in range(3))
