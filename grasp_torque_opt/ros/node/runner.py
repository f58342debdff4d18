# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
Running a node (the Jazzy pattern): spin in try, then destroy and shut down in finally.

Both executables (``grasp_torque_node``, ``grasp_torque_lifecycle_node``) run here:
their ROS arguments, the executor, the start-up check for a namesake, the executor
thread's priority, and the exit code (0, or 2 with one line on stderr).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
import ctypes
import sys

from grasp_torque_opt.backends import single_threaded_math
from grasp_torque_opt.core.exceptions import GraspTorqueError
from grasp_torque_opt.ros import realtime
from grasp_torque_opt.ros.node import signals
from grasp_torque_opt.ros.node.qos import NODE_NAME
from grasp_torque_opt.ros.node.waitset import WaitSetExecutor
from grasp_torque_opt.ros.node_help import node_parser
import rclpy
from rclpy.exceptions import NameValidationException, ParameterException
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import remove_ros_args

#: Longest wait of the spin loop without any callback [s]: how late a stop signal may be
#: seen when nothing else wakes the executor.
STOP_POLL_S = 0.1
#: Executors the runner can spin: the node's own wait-set loop (rclpy's single-threaded
#: executor, lighter per message: :mod:`~grasp_torque_opt.ros.node.waitset`), rclpy's own
#: and its experimental events executor.
EXECUTORS = {'waitset': WaitSetExecutor, 'single': SingleThreadedExecutor,
             'events': EventsExecutor}


#: glibc's mallopt parameters: the size from which malloc maps memory of its own, and
#: the free memory at the heap's top from which it is given back.
M_MMAP_THRESHOLD, M_TRIM_THRESHOLD = -3, -1
#: Buffers at least this large are mapped, and given back to the system when freed [B].
LARGE_BUFFER = 128 * 1024


def large_buffers_returned() -> bool:
    """
    Have glibc map every buffer of at least LARGE_BUFFER and give it back when freed.

    glibc raises both thresholds by itself after a large buffer is freed (the imports
    free some), and later ones of that size then stay in the heap: an oversized message
    (refused by ``max_message_bytes``) left one more such buffer resident with the
    node's own wait-set loop (test_node_memory). Fixed at glibc's defaults, the node's
    memory after oversized messages is what it was before them, whatever the executor.
    The node's per-message allocations are far smaller. False where the C library has
    no ``mallopt`` (musl).
    """
    try:
        libc = ctypes.CDLL(None)
        return bool(libc.mallopt(M_MMAP_THRESHOLD, LARGE_BUFFER)) and \
            bool(libc.mallopt(M_TRIM_THRESHOLD, LARGE_BUFFER))
    except (OSError, AttributeError):
        return False


def _init(prog: str, argv: list[str]) -> argparse.Namespace | None:
    """Parse the arguments and start rclpy; None (and one line on stderr) if refused."""
    parser = node_parser(prog)  # what it does, the --ros-args it takes, --version
    parser.add_argument('--executor', choices=sorted(EXECUTORS), default='waitset',
                        help="executor to spin: the node's own wait-set loop (waitset), "
                        "rclpy's SingleThreadedExecutor (single) or its EventsExecutor "
                        '(events)')
    try:
        opts = parser.parse_args(remove_ros_args(argv)[1:])
        single_threaded_math()
        large_buffers_returned()
        # rclpy's own handlers would shut the context down on SIGINT/SIGTERM, before the
        # safe action could publish; here both end the spin loop and the context stays
        # valid.
        rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    except Exception as e:  # noqa: B902 -- rcl's argument errors are pybind types of rclpy's
        # e.g. a --params-file that cannot be opened: rcl parses it before any node exists.
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        print(f'{prog}: error: ROS arguments: {first}', file=sys.stderr)
        return None
    return opts


def _refuse_namesake(node: Node) -> None:
    """Look for another node of this name for ``startup_check_time``; raise if one is."""
    wait = node.get_parameter('startup_check_time').value
    if wait <= 0.0:
        return
    node.get_logger().info(f'looking for another {NODE_NAME} on this domain ({wait:g} s)')
    if node.root.status.wait_for_duplicates(wait):
        raise GraspTorqueError(
            f'another node named {node.get_fully_qualified_name()} is on this domain '
            f'(ROS_DOMAIN_ID {node.context.get_domain_id()}): refusing to run, as both '
            'would drive effort_commands (stop it, or give this one another name with '
            '--ros-args -r __node:=NAME)')


def run(make_node: Callable[..., Node], prog: str, args: list[str] | None = None) -> int:
    """
    Run a node: spin until a stop signal, then destroy it and shut down.

    Besides the ROS arguments, ``--executor waitset|single|events`` picks the executor
    (default: the node's own wait-set loop, :mod:`~grasp_torque_opt.ros.node.waitset`).

    Args:
        make_node: the node's class (or a factory taking ``message_info``).
        prog: the executable's name, for messages.
        args: the command line (None: ``sys.argv``).

    Returns:
        The exit code: 0, or 2 with one line on stderr when the node refuses to run.
    """
    argv = sys.argv if args is None else args
    opts = _init(prog, argv)
    if opts is None:
        return 2
    previous = signals.install()
    node = executor = None
    code = 0
    try:
        node = make_node(message_info=opts.executor != 'events')
        _refuse_namesake(node)
        # rclpy's MultiThreadedExecutor managed 30 of 100 joint states a second here;
        # the single-threaded one keeps up (the service runs in its own worker).
        executor = EXECUTORS[opts.executor]()
        executor.add_node(node)
        # After the executor and the node made their threads: only this one is raised.
        priority = node.get_parameter('thread_priority').value
        fifo, what = realtime.set_fifo(priority)
        log = node.get_logger()
        (log.info if fifo or priority == 0 else log.warn)(f'executor thread: {what}')
        # A spin_once loop, so that the stop flag is seen: each wait ends by the next
        # watchdog tick (a steady timer) or after STOP_POLL_S, also while the managed node
        # is unconfigured and has no timer. (EventsExecutor.spin() also delivered no
        # subscription callback with these wheels, rclpy 7.1.6 and Fast DDS, while
        # keeping a core busy.)
        timeout = 1.0 if opts.executor == 'events' else STOP_POLL_S
        while not signals.stop_requested() and rclpy.ok():
            executor.spin_once(timeout_sec=timeout)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except (GraspTorqueError, ParameterException, NameValidationException) as e:
        # rclpy refuses a -p value out of a parameter's declared range or of the wrong
        # type while the node declares it, and a bad name or namespace (-r __node:=...).
        print(f'{prog}: error: {e}', file=sys.stderr)
        code = 2
    finally:
        if executor is not None:
            executor.shutdown(timeout_sec=1.0)  # its callbacks are off the entities first
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
        signals.restore(previous)
    return code


def main(args: list[str] | None = None) -> int:
    """Run the plain node ``grasp_torque_node``, which commands from its start."""
    from grasp_torque_opt.ros.node.plain import GraspTorqueNode

    return run(GraspTorqueNode, NODE_NAME, args)
