# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
What the demo and the simulated hand share: a private ROS domain, and the node as a child.

Both drivers can start ``grasp_torque_node`` themselves (``--with-node``) on the
same params file they read their scenario from, and stop it with SIGINT when
they end, so that its safe stop runs. The child's stderr is passed on line by line and
its last lines kept, so that a node that exits at start-up (a params file for another
hand, say) is named with its own error (:func:`startup_failure`), not taken for a node
that was never started.
"""

from __future__ import annotations

import collections
from collections.abc import Iterator
import contextlib
import os
from pathlib import Path
import signal
import subprocess
import sys
import threading

#: How many of the child's last stderr lines are kept.
KEPT_LINES = 20


def isolate() -> None:
    """
    Use a private ROS domain and localhost-only discovery, unless the caller set them.

    A ROS_DOMAIN_ID already set is the caller's choice and kept; without one, the
    first private domain of :mod:`~grasp_torque_opt.ros.domains` (a base from the
    process id, plus 1): the range the test suite and the benchmarks use, not a
    random draw.
    """
    from grasp_torque_opt.ros.domains import private

    os.environ.setdefault('ROS_DOMAIN_ID', str(private(0)))
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')


def scenario_of(params: Path) -> str:
    """Return the ``scenario`` parameter of a node params file."""
    import yaml

    doc = yaml.safe_load(params.read_text())
    return next(iter(doc.values()))['ros__parameters']['scenario']


@contextlib.contextmanager
def node_process(params: Path, start: bool, arguments: tuple[str, ...] = ()
                 ) -> Iterator[subprocess.Popen | None]:
    """
    ``grasp_torque_node`` on ``params`` in a child process while the block runs (if ``start``).

    ``arguments``: more ``--ros-args`` after the params file (``-p NAME:=VALUE``: the
    simulated driver's command interface).

    It is stopped with SIGINT (its safe stop: zero torques with the zero policy),
    killed if it has not ended after 10 s.
    """
    child = None
    if start:
        child = subprocess.Popen([sys.executable, '-m', 'grasp_torque_opt.ros.node',
                                  '--ros-args', '--params-file', str(params), *arguments,
                                  '--log-level', 'error'], stderr=subprocess.PIPE,
                                 text=True, errors='replace')
        child.last_lines = collections.deque(maxlen=KEPT_LINES)
        child.relay = threading.Thread(target=_relay, args=(child,), daemon=True)
        child.relay.start()
    try:
        yield child
    finally:
        if child is not None:
            child.send_signal(signal.SIGINT)
            try:
                child.wait(timeout=10)
            except subprocess.TimeoutExpired:
                child.kill()


def _relay(child: subprocess.Popen) -> None:
    """Pass the child's stderr on, line by line, keeping the last lines."""
    for line in child.stderr:
        child.last_lines.append(line.rstrip('\n'))
        sys.stderr.write(line)
        sys.stderr.flush()


def startup_failure(child: subprocess.Popen | None) -> str:
    """
    Return why the child node ended, in one line ('' while it runs, or with no child).

    The node's own error line (``grasp_torque_node: error: ...``) if it wrote one, else
    its last line on stderr, else its exit code alone.
    """
    if child is None or child.poll() is None:
        return ''
    relay = getattr(child, 'relay', None)
    if relay is not None:
        relay.join(timeout=2.0)  # the rest of its stderr
    lines = [line for line in getattr(child, 'last_lines', ()) if line.strip()]
    errors = [line for line in lines if ': error: ' in line]
    said = (errors or lines or [''])[-1].strip()
    said = said.removeprefix('grasp_torque_node: ')
    return (f'grasp_torque_node exited with code {child.returncode} at start-up'
            + (f': {said}' if said else ''))
