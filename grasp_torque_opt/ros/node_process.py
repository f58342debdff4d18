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
they end, so that its safe stop runs.
"""

from __future__ import annotations

from collections.abc import Iterator
import contextlib
import os
from pathlib import Path
import signal
import subprocess
import sys


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
def node_process(params: Path, start: bool, overrides: tuple[str, ...] = ()
                 ) -> Iterator[subprocess.Popen | None]:
    """
    ``grasp_torque_node`` on ``params`` in a child process while the block runs (if ``start``).

    ``overrides``: ``NAME:=VALUE`` parameters given after the file (``-p``).

    It is stopped with SIGINT (its safe stop: zero torques with the zero policy),
    killed if it has not ended after 10 s.
    """
    child = None
    if start:
        extra = [arg for o in overrides for arg in ('-p', o)]
        child = subprocess.Popen([sys.executable, '-m', 'grasp_torque_opt.ros.node',
                                  '--ros-args', '--params-file', str(params), *extra,
                                  '--log-level', 'error'])
    try:
        yield child
    finally:
        if child is not None:
            child.send_signal(signal.SIGINT)
            try:
                child.wait(timeout=10)
            except subprocess.TimeoutExpired:
                child.kill()
