# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The executor thread's scheduling: SCHED_FIFO where the system allows it.

ros2_control's controller_manager asks SCHED_FIFO at priority 50 for its main
thread, whatever the kernel, and goes on with a warning where it is refused;
the node's executables do the same for the thread that spins the node (the
``thread_priority`` parameter). Only that thread: threads it starts afterwards
(the ``~/solve`` worker, the tf listener's) would inherit the policy, so they
put themselves back to normal scheduling with :func:`normal_scheduling`.
"""

from __future__ import annotations

import os
import sys

#: Python's thread switch interval once the spinning thread is SCHED_FIFO [s]. The
#: ``~/solve`` worker shares the interpreter lock with the loop; at Python's 5 ms a
#: cycle could wait that long for it. In a 240 s soak with service floods (seed 3)
#: the SCHED_FIFO node had 8 overruns and 5 solver failures at 5 ms and none at
#: 0.5 ms (nor with normal scheduling), and answered the most joint states.
FIFO_SWITCH_INTERVAL_S = 5e-4

#: How a user lets a process ask for a real-time priority (control.ros.org's recipe).
HOW_TO = ('give the user an rtprio limit (e.g. /etc/security/limits.conf: '
          "'@realtime hard rtprio 99') or CAP_SYS_NICE (docker: --cap-add=sys_nice "
          '--ulimit rtprio=99)')


def set_fifo(priority: int) -> tuple[bool, str]:
    """
    Ask SCHED_FIFO at ``priority`` for the calling thread.

    Granted, Python's thread switch interval becomes at most
    :data:`FIFO_SWITCH_INTERVAL_S` (for the whole process).

    Args:
        priority: 1 to 99; 0 leaves the thread's scheduling as it is.

    Returns:
        (whether the thread now runs SCHED_FIFO at ``priority``, what happened in words).
    """
    if priority <= 0:
        return False, 'left as it is (thread_priority 0)'
    if not hasattr(os, 'sched_setscheduler'):
        return False, 'this platform has no SCHED_FIFO'
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except OSError as e:  # EPERM without the right: the thread stays as it was
        return False, f'SCHED_FIFO {priority} refused ({e.strerror}): {HOW_TO}'
    sys.setswitchinterval(min(sys.getswitchinterval(), FIFO_SWITCH_INTERVAL_S))
    return True, f'SCHED_FIFO {priority}, switch interval {1e3 * sys.getswitchinterval():g} ms'


def normal_scheduling() -> None:
    """Put the calling thread on SCHED_OTHER (a thread started by a SCHED_FIFO one)."""
    if hasattr(os, 'sched_setscheduler'):
        try:
            os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
        except OSError:  # lowering is always allowed; nothing else to do if not
            pass


def describe() -> str:
    """Say the calling thread's scheduling, e.g. ``SCHED_FIFO 50`` or ``SCHED_OTHER``."""
    if not hasattr(os, 'sched_getscheduler'):
        return 'unknown on this platform'
    policy = os.sched_getscheduler(0)
    names = {getattr(os, n): n for n in ('SCHED_OTHER', 'SCHED_FIFO', 'SCHED_RR',
                                         'SCHED_BATCH', 'SCHED_IDLE') if hasattr(os, n)}
    name = names.get(policy, f'policy {policy}')
    if policy in (getattr(os, 'SCHED_FIFO', None), getattr(os, 'SCHED_RR', None)):
        return f'{name} {os.sched_getparam(0).sched_priority}'
    return name
