# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Pieces shared by the ROS 2 benchmarks ``node_load.py`` and ``soak.py``.

Child processes on a private ROS domain (stopped with their whole process
group, whatever happens), the command line of ``grasp_torque_node``, a pacer
that publishes on absolute deadlines while it spins the receiver, and stamps
as integer nanoseconds so that a command can be matched to its joint state.
"""

from __future__ import annotations

import os
from pathlib import Path
import resource
import signal
import subprocess
import sys
import time
from typing import Callable, IO

from grasp_torque_opt.ros.domains import private
import numpy as np

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
CONFIG = ROOT / 'config'
#: The node's stamped commands, whatever answers on joint_states (node or echo).
STAMPED_TOPIC = '/grasp_torque_node/effort_commands_stamped'
#: Depth of the receiver's command queue (reliable). The node publishes with depth 1;
#: a receiver with depth 1 would lose a command whenever two arrive between two of
#: its own callbacks, and count the receiver's drops as the node's.
RECEIVER_DEPTH = 1000
#: Before a deadline the pacer stops waiting for messages and busy-waits [s].
BUSY_WAIT_S = 300e-6


def private_domains(n: int) -> list[int]:
    """
    Return the ROS domains of ``n`` runs: ROS_DOMAIN_ID + 1 to + SPAN in turn.

    The rule of grasp_torque_opt.ros.domains.

    Consecutive runs never share one; ROS_DOMAIN_ID itself is left alone.
    """
    return [private(k) for k in range(n)]


def isolated_env(domain: int) -> dict[str, str]:
    """Return the environment of every process of a run: a private domain, localhost only."""
    env = dict(os.environ)
    env['ROS_DOMAIN_ID'] = str(domain)
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    env.pop('ROS_STATIC_PEERS', None)
    env['PYTHONUNBUFFERED'] = '1'
    return env


def node_command(params: Path, executor: str, extra: list[str] | None = None) -> list[str]:
    """Command line of ``grasp_torque_node`` on a params file, stamped commands on."""
    exe = Path(sys.executable).parent / 'grasp_torque_node'
    head = [str(exe)] if exe.exists() else [sys.executable, '-m', 'grasp_torque_opt.ros.node']
    return head + ['--executor', executor, '--ros-args', '--params-file', str(params),
                   '-p', 'publish_stamped_command:=true'] + (extra or [])


class Child:
    """
    A child process in its own process group; :meth:`stop` ends the whole group.

    Args:
        cmd: command line.
        env: its environment.
        log: file that takes its stdout and stderr.
    """

    def __init__(self, cmd: list[str], env: dict[str, str], log: IO) -> None:
        self.cmd = cmd
        self.proc = subprocess.Popen(cmd, env=env, stdout=log, stderr=subprocess.STDOUT,
                                     stdin=subprocess.DEVNULL, start_new_session=True)

    @property
    def pid(self) -> int:
        return self.proc.pid

    def alive(self) -> bool:
        return self.proc.poll() is None

    def stop(self, grace_s: float = 5.0) -> int | None:
        """SIGINT to the group (a clean ROS shutdown), then SIGKILL after ``grace_s``."""
        if self.proc.poll() is None:
            self._signal(signal.SIGINT)
            try:
                self.proc.wait(timeout=grace_s)
            except subprocess.TimeoutExpired:
                pass
        self._signal(signal.SIGKILL)  # anything the child left in its group
        try:
            return self.proc.wait(timeout=grace_s)
        except subprocess.TimeoutExpired:
            return None

    def _signal(self, sig: int) -> None:
        try:
            os.killpg(self.proc.pid, sig)
        except (ProcessLookupError, PermissionError):
            pass


def interrupt_on_signals() -> None:
    """
    SIGINT and SIGTERM raise KeyboardInterrupt, so that ``finally`` blocks stop the children.

    SIGINT too: a process started in the background by a non-interactive shell
    inherits it ignored.
    """
    def handler(signum, frame):  # noqa: ARG001 -- signal handler signature
        raise KeyboardInterrupt
    signal.signal(signal.SIGTERM, handler)
    signal.signal(signal.SIGINT, signal.default_int_handler)


def stamp_ns(stamp) -> int:
    """Convert a builtin_interfaces/Time to integer nanoseconds."""
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def set_stamp(header, ns: int) -> None:
    """Stamp a std_msgs/Header with integer nanoseconds (system clock, as ROS time)."""
    header.stamp.sec, header.stamp.nanosec = divmod(ns, 1_000_000_000)


class UniqueClock:
    """System time [ns], strictly increasing between calls: every stamp names one message."""

    def __init__(self) -> None:
        self._last = 0

    def __call__(self) -> int:
        ns = time.time_ns()
        if ns <= self._last:
            ns = self._last + 1
        self._last = ns
        return ns


class Pacer:
    """
    Calls ``tick`` on absolute deadlines at ``rate`` and spins ``executor`` in between.

    Until ``BUSY_WAIT_S`` before a deadline it serves the receiver's callbacks
    (``spin_once`` with a timeout that ends there); then it busy-waits to the
    deadline. Deadlines are absolute (start + k / rate): a late tick does not
    shift the ones after it, so the count over a window is exact.

    Args:
        executor: rclpy executor holding the receiving node.
        rate: ticks per second [Hz].
    """

    def __init__(self, executor, rate: float) -> None:
        self.executor = executor
        self.period = 1.0 / rate
        self.lateness: list[float] = []  # tick start minus its deadline [s]

    def run(self, tick: Callable[[int, float], bool], start: float | None = None) -> None:
        """Tick k at start + k * period until ``tick(k, now)`` returns False."""
        t0 = time.perf_counter() if start is None else start
        k = 0
        while True:
            deadline = t0 + k * self.period
            while (rest := deadline - time.perf_counter()) > BUSY_WAIT_S:
                self.executor.spin_once(timeout_sec=rest - BUSY_WAIT_S)
            while (now := time.perf_counter()) < deadline:
                pass
            self.lateness.append(now - deadline)
            if not tick(k, now):
                return
            k += 1

    def spin_for(self, seconds: float) -> None:
        """Serve callbacks only, for ``seconds``."""
        end = time.perf_counter() + seconds
        while (rest := end - time.perf_counter()) > 0:
            self.executor.spin_once(timeout_sec=rest)


def percentiles_ms(values_s: list[float] | np.ndarray) -> dict[str, float | None]:
    """p50, p99 and max [ms] of samples in seconds (None when there are none)."""
    if len(values_s) == 0:
        return {'p50_ms': None, 'p99_ms': None, 'max_ms': None}
    v = 1e3 * np.asarray(values_s, dtype=float)
    return {'p50_ms': float(np.percentile(v, 50)), 'p99_ms': float(np.percentile(v, 99)),
            'max_ms': float(v.max())}


def process_cpu_s(pid: int | None) -> float | None:
    """Return the CPU time a process used so far, user and system [s] (None: unknown)."""
    if pid is None:
        return None
    try:
        stat = Path(f'/proc/{pid}/stat').read_text()
    except OSError:
        return None
    fields = stat.rsplit(')', 1)[1].split()  # after the command name, which may hold spaces
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


class CpuShare:
    """
    CPU used by processes other than this one and its reaped children, over an interval.

    The machine may be shared: this says how much of it the benchmark had.
    Start it before the children, call :meth:`others_cores` after they were reaped,
    or name the children still running in ``exclude``: their CPU time is not "other".
    "Other" is the machine's busy time (/proc/stat) that no process of the benchmark
    was charged with: other processes, but also the kernel's interrupt work (the
    benchmark's own DDS traffic on the loopback included) and, on a VM, the time the
    hypervisor took (steal).

    Args:
        exclude: pids of running children that belong to the benchmark.
    """

    def __init__(self, exclude: tuple[int, ...] = ()) -> None:
        self._t = time.monotonic()
        self._busy = self._busy_s()
        self._own = self._own_s()
        self._exclude = {pid: process_cpu_s(pid) or 0.0 for pid in exclude}

    @staticmethod
    def _busy_s() -> float:
        fields = [int(x) for x in Path('/proc/stat').read_text().split('\n', 1)[0].split()[1:]]
        idle = fields[3] + fields[4]  # idle, iowait
        return (sum(fields[:8]) - idle) / os.sysconf('SC_CLK_TCK')

    @staticmethod
    def _own_s() -> float:
        me = resource.getrusage(resource.RUSAGE_SELF)
        kids = resource.getrusage(resource.RUSAGE_CHILDREN)
        return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime

    def cores_of(self, pid: int) -> float | None:
        """Return the mean cores an excluded child used since the start (None: unknown)."""
        now = process_cpu_s(pid)
        if now is None or pid not in self._exclude:
            return None
        return (now - self._exclude[pid]) / (time.monotonic() - self._t)

    def others_cores(self) -> float | None:
        """Return the mean number of cores busy with other work since the start."""
        try:
            busy = self._busy_s() - self._busy
        except OSError:
            return None
        kids = sum((process_cpu_s(pid) or start) - start for pid, start in self._exclude.items())
        return max(0.0, busy - (self._own_s() - self._own) - kids) / (time.monotonic() - self._t)


def vm_rss_kib(pid: int) -> int | None:
    """Resident set size of a process [KiB], from /proc (None if it is gone)."""
    try:
        for line in Path(f'/proc/{pid}/status').read_text().splitlines():
            if line.startswith('VmRSS:'):
                return int(line.split()[1])
    except OSError:
        return None
    return None
