# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
ROS 2 node ``grasp_torque_node``: certified grasp torques every cycle, and a solve service.

A thin adapter over :class:`grasp_torque_opt.control.controller.TorqueController`:
messages in, plain arrays to the controller, its decisions out. Interface
pinned in docs/design.md section 4; parameters, units and defaults in docs/design.md section 4.4.

:class:`GraspTorqueCore` is what the plain node here and the managed (lifecycle) node
of :mod:`grasp_torque_opt.ros.lifecycle_node` share: loading the grasp, the
parameters, the inputs, the cycle, the outputs and the service. The plain node does
all of it at construction and commands at once (docs/node.md, "Plain or managed").
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
import dataclasses
from dataclasses import dataclass
import importlib.util
import math
import signal
import sys
import threading
import time
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Point, PoseArray, Vector3Stamped, WrenchStamped
from grasp_torque_opt.backends import (
    available,
    BACKENDS,
    make_solver,
    single_threaded_math,
)
from grasp_torque_opt.backends.proxsuite import ProxSuiteSettings
from grasp_torque_opt.control import compiled, diagnostics
from grasp_torque_opt.control.controller import (
    CycleConfig,
    CycleResult,
    MAX_GRAVITY,
    POLICIES,
    quaternion_matrix,
    stamp_seconds,
    TorqueController,
)
from grasp_torque_opt.core.exceptions import (
    cut,
    FrameNotFound,
    GraspTorqueError,
    InputError,
    JointNotFound,
    quote,
)
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import Hand, MAX_TORQUE_LIMIT, MAX_URDF_BYTES
from grasp_torque_opt.core.report import solution_dict, strict_json
from grasp_torque_opt.core.resources import decode_utf8, find_config, read_bounded
from grasp_torque_opt.core.scenario import (
    load_scenario,
    MAX_NAME_MAP,
    OBJECTIVES,
    parse_name_map,
    Scenario,
    weight_wrench,
)
from grasp_torque_opt.ros import realtime
from grasp_torque_opt.ros.peers import PeerWatch, quiet_publisher, quiet_subscription, summary
import numpy as np
from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    SetParametersResult,
)
import rclpy
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.duration import Duration
from rclpy.exceptions import (
    InvalidTopicNameException,
    NameValidationException,
    ParameterException,
    ParameterNotDeclaredException,
    ParameterUninitializedException,
)
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    qos_profile_sensor_data,
    QoSProfile,
    ReliabilityPolicy,
)
from rclpy.serialization import deserialize_message
from rclpy.signals import SignalHandlerOptions
from rclpy.task import Future
from rclpy.time import Time
from rclpy.utilities import remove_ros_args
from rclpy.validate_topic_name import validate_topic_name
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray, String
from std_srvs.srv import Trigger
from visualization_msgs.msg import Marker, MarkerArray

NODE_NAME = 'grasp_torque_node'
#: Commands: reliable, only the newest matters.
COMMAND_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE)
#: joint_states: sensor data QoS (best effort, volatile) with only the newest state kept.
#: When a cycle takes longer than the publisher's period, the next cycle runs on the
#: latest joint state, not on a queue of older ones: with sensor data's keep last 5, the
#: Allegro node at 1 kHz answered 5.5 ms (median) after the stamp here, working off the
#: queue; the other inputs only set state, so their depth costs nothing.
JOINT_STATE_QOS = QoSProfile(depth=1, history=HistoryPolicy.KEEP_LAST,
                             reliability=ReliabilityPolicy.BEST_EFFORT,
                             durability=DurabilityPolicy.VOLATILE)
#: ~/solve: reliable, every request kept until it is taken (keep last 100 dropped 872 to
#: 900 of 1000 concurrent calls silently); the node answers each, "busy" beyond
#: MAX_PENDING_SOLVES.
SERVICE_QOS = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE)
#: Solves the service queues for its worker (each a snapshot of the inputs); a request
#: beyond them is answered "busy" at once.
MAX_PENDING_SOLVES = 100
#: robot_description as robot_state_publisher publishes it: reliable, transient local.
URDF_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL)
#: Serialized std_msgs/String beyond the URDF's own bytes (CDR header, length, NUL).
URDF_MESSAGE_OVERHEAD = 64


@dataclass(frozen=True)
class Spec:
    """One parameter: description (with unit), range, and whether it can change at run time."""

    description: str
    low: float | None = None
    high: float | None = None
    read_only: bool = False
    length: str | None = None  # "joints" or a number, for arrays


#: Every parameter, declared in this order. Defaults come from the scenario.
PARAMETERS: dict[str, Spec] = {
    'scenario': Spec('Scenario file (docs/design.md section 4): hand, default contacts and load. '
                     "A path, or the name of a bundled file in the package's config/.",
                     read_only=True),
    'robot_description': Spec('URDF document of the hand (the ROS convention) or a path to '
                              'one; empty: the URDF from robot_description_topic if set, '
                              "else the scenario's hand.urdf.", read_only=True),
    'robot_description_topic': Spec('Topic to take the URDF from (std_msgs/String, reliable, '
                                    'transient local, as robot_state_publisher publishes '
                                    "it, e.g. 'robot_description') when robot_description "
                                    "is empty; '': none. Waited for at start (the managed "
                                    'node: at configure) up to robot_description_timeout.',
                                    read_only=True),
    'robot_description_timeout': Spec('How long the node waits for the URDF on '
                                      'robot_description_topic before it gives up [s].',
                                      0.1, 300.0, read_only=True),
    'name_map': Spec("The scenario's joint and frame names to the URDF's, as "
                     "'SCENARIO_NAME=URDF_NAME' entries, over the scenario's "
                     'hand.name_map; applied before any name is checked. Unset: none.',
                     read_only=True),
    'joints': Spec("Actuated joints in command order (default: the scenario's).",
                   read_only=True),
    'object_origin': Spec('Object origin c in the base frame [m].', length='3'),
    'mu_tangential': Spec('Tangential friction coefficient mu1 [-].', 1e-6, 10.0),
    'mu_torsional': Spec('Torsional friction coefficient mu2 [m].', 1e-9, 1.0),
    'polygon_sides': Spec('Sides N of the inscribed friction polygon [-].', 3, 64),
    'min_normal_force': Spec('Minimum normal force per contact [N].', 0.0, 1000.0),
    'torque_limits': Spec('|command_i| <= torque_limits[i] [N m], per joint; each at most '
                          "the joint's URDF effort limit (the scenario's limit if the URDF "
                          'gives none) unless torque_limits_above_urdf.', length='joints'),
    'torque_limits_above_urdf': Spec("Allow torque_limits above the URDF's effort limits (up "
                                     "to 1e4 N m); default: the scenario's "
                                     'hand.torque_limits_above_urdf.', read_only=True),
    'weights': Spec('Objective weights W (diagonal), per joint, each in [1e-6, 1e6], the '
                    'largest at most 1e6 times the smallest [-].', length='joints'),
    'friction_margin': Spec('Friction margin k: plan inside the cone of mu/(1+k), so the '
                            'commanded wrenches hold with up to (1+k) times less friction '
                            '(docs/planner.md) [-].', 0.0, 100.0),
    'objective': Spec("'sum-of-squares' (the paper's, default: the scenario's) or 'min-max' "
                      '(max |tau_i + g_i| / limit_i, an LP, then the sum of squares among its '
                      'optima; docs/planner.md).'),
    'gravity_compensation': Spec("Add the fingers' own gravity torques g(q); the torque "
                                 'limits then bound the sum.'),
    'gravity': Spec("Gravity in the base frame for g(q) [m/s^2]; default: the scenario's "
                    'gravity, else [0, 0, -9.81].', length='3'),
    'joint_state_timeout': Spec('Joint states older than this stop commands [s].', 1e-4, 10.0),
    'contacts_timeout': Spec('Once contacts arrived, older than this stop commands [s]; '
                             '0: never stale.', 0.0, 60.0),
    'wrench_timeout': Spec('Once a load arrived, older than this stops commands [s]; '
                           '0: never stale.', 0.0, 60.0),
    'gravity_timeout': Spec('Once gravity arrived on the gravity topic, older than this '
                            'stops commands [s]; 0: never stale.', 0.0, 60.0),
    'hold_time': Spec('How long a fault may hold the last certified command before the '
                      'fault policy applies [s].', 0.0, 60.0),
    'fault_policy': Spec("After hold_time in a fault: 'hold' (publish nothing, the effort "
                         "controller keeps the last certified command) or 'zero' (publish "
                         'zero torques).'),
    'max_message_bytes': Spec('A message on joint_states, contacts, external_wrench or '
                              'gravity whose serialized form is longer than this is rejected '
                              'before it is deserialized [bytes].', 1024, 16777216),
    'max_joint_state_entries': Spec('A joint state with more names or positions than this is '
                                    'rejected unread [-].', 1, 100000),
    'max_wrench_force': Spec('A load whose force norm exceeds this is rejected [N].',
                             1e-6, 1e6),
    'max_wrench_torque': Spec('A load whose moment norm exceeds this is rejected [N m].',
                              1e-6, 1e6),
    'max_contact_distance': Spec('A contact point farther than this from the base origin '
                                 'stops commands [m].', 1e-3, 100.0),
    'stamp_future_tolerance': Spec("A header stamp more than this ahead of the node's clock "
                                   'is rejected [s].', 0.0, 3600.0),
    'cycle_budget': Spec('A cycle that takes longer publishes nothing (overrun); its '
                         'solvers stop by it (or by joint_state_timeout if smaller) [s].',
                         1e-4, 1.0),
    'solver.method': Spec("'tau-qp' (default: the paper's N-gon) or 'tau-qp-adaptive' (the "
                          'exact-cone optimum from QPs with a certified gap to it, '
                          "docs/adaptive.md; needs DAQP; about 3 times tau-qp's cycle with "
                          'DAQP, well within the default cycle_budget).'),
    'solver.backend': Spec("QP backend: 'proxsuite' (default), 'daqp' or 'quadprog' (grasps "
                           'without internal-force variables only); every result is '
                           'certified whichever solves it.'),
    'solver.fallback': Spec('Backend asked in the same cycle when solver.backend gives nothing '
                            "certifiable ('none': no second try); its answer is certified "
                            'the same way and counted (diagnostics solver.fallback_solves).'),
    'solver.warm_start': Spec("Start each solve from the previous cycle's (ProxSuite: its "
                              'result, preconditioner kept; DAQP: its active set); an answer '
                              'that is not solved, fails the KKT check or is not certified '
                              'is redone cold in the same cycle and counted (diagnostics '
                              'solver.warm_start_fallbacks). No effect on quadprog.'),
    'solver.compiled': Spec('Run the cycle compiled (maps, build, ProxSuite solve and '
                            'certificate in C++, src/fast_cycle.hpp) where it applies: '
                            'tau-qp, sum-of-squares, ProxSuite, no internal-force variables. '
                            'Elsewhere, and on any answer it cannot certify, the Python '
                            'cycle answers (diagnostics solver.compiled). false: the Python '
                            'cycle always.'),
    'solver.eps_abs': Spec('Solver absolute tolerance (ProxSuite eps_abs, DAQP primal_tol) '
                           '[-].', 1e-12, 1e-4),
    'solver.max_iter': Spec('Solver iteration cap (ProxSuite outer, DAQP) [-].', 1, 10000),
    'solver.max_iter_in': Spec('ProxSuite inner iteration cap; one outer iteration, up to '
                               'this many inner ones, is how far a solve can run past its '
                               'budget [-].', 1, 200),
    'certificate_tolerance': Spec('Tolerance of the certificate on every residual [SI].',
                                  1e-12, 1e-2),
    'diagnostics_period': Spec('Period of /diagnostics [s] (1 Hz, as diagnostic_updater).',
                               1e-3, 60.0, read_only=True),
    'marker_period': Spec('Period of ~/contact_wrenches [s]; each arrow lives three periods, '
                          'so they vanish when the node stops.', 1e-3, 60.0, read_only=True),
    'watchdog_period': Spec('Period of the staleness check between joint states [s].',
                            1e-4, 1.0, read_only=True),
    'startup_check_time': Spec('At start, how long grasp_torque_node looks for another node '
                               'of its name on the domain before it takes any input; one '
                               'found: it exits with an error (code 2). Later, one is '
                               'reported (diagnostics ERROR) [s].', 0.0, 30.0, read_only=True),
    'thread_priority': Spec('At start, the SCHED_FIFO priority the executables ask for the '
                            "thread that spins the node (ros2_control's controller_manager asks "
                            '50 for its loop); where the system refuses, a warning and normal '
                            'scheduling; 0 (the default): the scheduling is left as it is [-].',
                            0, 99, read_only=True),
    'marker_scale': Spec('Arrow length per newton in ~/contact_wrenches [m/N].', 0.0, 10.0),
    'publish_stamped_command': Spec('Also publish each command on ~/effort_commands_stamped '
                                    '(sensor_msgs/JointState: joints, effort, and the stamp of '
                                    'the joint state it was computed from).', read_only=True),
}


def received(info: dict | None) -> float:
    """
    When the middleware received a message, on the monotonic clock [s].

    rmw's message info carries ``received_timestamp``: the system clock
    (``CLOCK_REALTIME``) of this host when the subscription's middleware took the
    message in, before it waited in the queue for the executor. Its age on the
    system clock, taken from now on the monotonic clock, is the receipt time
    (a clock step between the two counts as no wait; a message without it: now).
    """
    now = time.monotonic()
    ns = (info or {}).get('received_timestamp') or 0
    if ns <= 0:
        return now
    return now - max(0.0, (time.time_ns() - ns) * 1e-9)


#: Parameters whose defaults come from the scenario (and its hand), and their types:
#: the managed node declares them without a value until configure fills them in.
SCENARIO_PARAMETERS = {
    'joints': Parameter.Type.STRING_ARRAY,
    'torque_limits_above_urdf': Parameter.Type.BOOL,
    'object_origin': Parameter.Type.DOUBLE_ARRAY,
    'mu_tangential': Parameter.Type.DOUBLE,
    'mu_torsional': Parameter.Type.DOUBLE,
    'polygon_sides': Parameter.Type.INTEGER,
    'min_normal_force': Parameter.Type.DOUBLE,
    'torque_limits': Parameter.Type.DOUBLE_ARRAY,
    'weights': Parameter.Type.DOUBLE_ARRAY,
    'friction_margin': Parameter.Type.DOUBLE,
    'objective': Parameter.Type.STRING,
    'gravity': Parameter.Type.DOUBLE_ARRAY,
}
#: The constraint a read-only parameter of the plain node has in the managed node.
FIXED_WHILE_CONFIGURED = 'fixed while configured: set it while unconfigured, then configure'


def fixed_defaults() -> dict[str, Any]:
    """
    Give the defaults of the parameters that do not depend on the scenario.

    ``name_map`` is not among them: it is declared without a value (unset: no map),
    as ROS parameters cannot hold an empty list of a known type.
    """
    return {
        'scenario': '',
        'robot_description': '',
        'robot_description_topic': '',
        'robot_description_timeout': 10.0,
        'gravity_compensation': False,
        'joint_state_timeout': 0.1,
        'contacts_timeout': 0.5,
        'wrench_timeout': 0.5,
        'gravity_timeout': CycleConfig.gravity_timeout,
        'hold_time': 0.1,
        'fault_policy': 'hold',
        'max_message_bytes': CycleConfig.max_message_bytes,
        'max_joint_state_entries': CycleConfig.max_joint_state_entries,
        'max_wrench_force': CycleConfig.max_wrench_force,
        'max_wrench_torque': CycleConfig.max_wrench_torque,
        'max_contact_distance': CycleConfig.max_contact_distance,
        'stamp_future_tolerance': CycleConfig.stamp_future_tolerance,
        'cycle_budget': CycleConfig.cycle_budget,
        'solver.method': 'tau-qp',
        'solver.backend': BACKENDS[0],
        'solver.fallback': 'daqp',
        'solver.warm_start': True,
        'solver.compiled': True,
        'solver.eps_abs': ProxSuiteSettings.eps_abs,
        'solver.max_iter': ProxSuiteSettings.max_iter,
        'solver.max_iter_in': ProxSuiteSettings.max_iter_in,
        'certificate_tolerance': CycleConfig.certificate_tolerance,
        'diagnostics_period': 1.0,
        'marker_period': 0.1,
        'watchdog_period': 0.01,
        'startup_check_time': 2.0,
        'thread_priority': 0,  # opt-in: docs/node.md, "The executor thread's priority"
        'marker_scale': 0.02,
        'publish_stamped_command': False,
    }


def scenario_defaults(scenario: Scenario, setup: GraspSetup) -> dict[str, Any]:
    """Give the defaults of :data:`SCENARIO_PARAMETERS` from a scenario bound to its hand."""
    return {
        'joints': list(setup.hand.joints),
        'torque_limits_above_urdf': scenario.torque_limits_above_urdf,
        'object_origin': [float(x) for x in setup.object_origin],
        'mu_tangential': setup.friction.mu1,
        'mu_torsional': setup.friction.mu2,
        'polygon_sides': setup.friction.sides,
        'min_normal_force': setup.friction.min_normal_force,
        'torque_limits': [float(x) for x in setup.hand.torque_limits],
        'weights': [float(x) for x in setup.weights],
        'friction_margin': setup.friction.margin,
        'objective': setup.objective,
        # One place for gravity: the scenario's, which also gives its load.
        'gravity': ([float(x) for x in scenario.gravity] if scenario.gravity is not None
                    else [0.0, 0.0, -9.81]),
    }


def name_map_of(entries: list[str] | None) -> dict[str, str]:
    """
    Parse the ``name_map`` parameter: entries ``SCENARIO_NAME=URDF_NAME``.

    Args:
        entries: the parameter's value (None or empty: no map).

    Returns:
        scenario name -> URDF name.

    Raises:
        InputError: an entry without one ``=`` between two names, a name mapped
            twice, two names mapped to one, more than MAX_NAME_MAP entries.
    """
    if not entries:
        return {}
    if len(entries) > MAX_NAME_MAP:
        raise InputError('name_map', f'{len(entries)} entries, more than {MAX_NAME_MAP}')
    out: dict[str, str] = {}
    for i, entry in enumerate(entries):
        key, sep, target = (part.strip() for part in str(entry).partition('='))
        if not sep or not key or not target or '=' in target:
            raise InputError(f'name_map[{i}]', f'must be SCENARIO_NAME=URDF_NAME, got '
                             f'{quote(entry)}')
        if key in out:
            raise InputError(f'name_map[{i}]', f"maps '{cut(key)}' a second time")
        out[key] = target
    return parse_name_map(out, 'name_map')


def descriptor(name: str, managed: bool = False) -> ParameterDescriptor:
    """
    Build the ParameterDescriptor of a parameter of :data:`PARAMETERS`.

    Args:
        name: the parameter.
        managed: for the managed node, where a parameter that is read-only in the
            plain node can be set while unconfigured (and is refused while configured).
    """
    spec = PARAMETERS[name]
    d = ParameterDescriptor(name=name, description=spec.description,
                            read_only=spec.read_only and not managed)
    if managed and spec.read_only:
        d.additional_constraints = FIXED_WHILE_CONFIGURED
    if spec.low is not None and isinstance(spec.low, int) and isinstance(spec.high, int):
        d.integer_range = [IntegerRange(from_value=spec.low, to_value=spec.high, step=1)]
    elif spec.low is not None:
        d.floating_point_range = [FloatingPointRange(from_value=float(spec.low),
                                                     to_value=float(spec.high), step=0.0)]
    return d


#: Values of ``solver.method``: the product's methods (the references are not for a cycle).
CYCLE_METHODS = ('tau-qp', 'tau-qp-adaptive')
#: Values of ``solver.fallback``.
FALLBACKS = (*BACKENDS, 'none')
#: Each weight's range, and the largest ratio of two weights: W's condition number
#: bounds how hard the QP is (ratios of 1e12 and more kept ProxSuite at its caps).
WEIGHT_RANGE = (1e-6, 1e6)
MAX_WEIGHT_RATIO = 1e6
#: Longest ProxSuite call of a ``~/solve`` request [s]: the service's worker shares
#: Python's interpreter lock with the control loop, which ProxSuite holds while it runs.
SERVICE_SLICE_S = 0.005


def _fallback(backend: str, fallback: str) -> str | None:
    """
    Name the fallback backend to build, or None.

    None for 'none', the backend itself, or one not installed (a ROS distribution may
    lack DAQP; the node then runs without a second try).
    """
    return None if fallback in ('none', backend) or not available(fallback) else fallback


def check(name: str, value: Any, m: int | None, torque_bounds: np.ndarray | None = None,
          joints: list[str] | None = None) -> str:
    """
    Say why a parameter value is refused ('' if accepted). Ranges are checked by rclpy too.

    Args:
        name: the parameter.
        value: its new value.
        m: number of joints (None: no hand loaded yet, the count is not checked).
        torque_bounds: the largest value of each torque limit [N m] (None: unchecked).
        joints: joint names, for messages.
    """
    spec = PARAMETERS[name]
    if name == 'name_map':
        try:
            name_map_of(value)
        except InputError as e:
            return str(e)
        return ''
    if name == 'robot_description_topic':
        if not value:
            return ''
        try:
            validate_topic_name(value)
        except InvalidTopicNameException as e:
            return f'{name}: ' + str(e).splitlines()[0]
        return ''
    if name == 'scenario' or name == 'robot_description' or name == 'joints':
        return ''
    if name == 'fault_policy':
        return '' if value in POLICIES else f"{name}: must be one of {', '.join(POLICIES)}"
    if name == 'solver.backend':
        if value not in BACKENDS:
            return f"{name}: must be one of {', '.join(BACKENDS)}"
        if not available(value):
            return f'{name}: {value} is not installed (pip install {value})'
        return ''
    if name == 'solver.fallback':
        return '' if value in FALLBACKS else f"{name}: must be one of {', '.join(FALLBACKS)}"
    if name == 'solver.method':
        if value not in CYCLE_METHODS:
            return f"{name}: must be one of {', '.join(CYCLE_METHODS)}"
        return '' if value == 'tau-qp' or available('daqp') else \
            f'{name}: {value} needs daqp, which is not installed (pip install daqp)'
    if name == 'objective':
        return '' if value in OBJECTIVES else f"{name}: must be one of {', '.join(OBJECTIVES)}"
    if spec.length is not None:
        n = m if spec.length == 'joints' else int(spec.length)
        values = list(value)
        if n is not None and len(values) != n:
            return f'{name}: must have {n} entries, got {len(values)}'
        if not all(math.isfinite(v) for v in values):
            return f'{name}: must be finite'
        if name in ('torque_limits', 'weights') and not all(v > 0 for v in values):
            return f'{name}: every entry must be > 0'
        if name == 'torque_limits' and torque_bounds is not None:
            try:
                Hand.check_limits(np.array(values, dtype=float), joints or [], torque_bounds,
                                  name, 'torque_limits_above_urdf (read-only: at start)')
            except InputError as e:
                return str(e)
        if name == 'gravity' and math.sqrt(sum(v * v for v in values)) > MAX_GRAVITY:
            return f'{name}: norm must be at most {MAX_GRAVITY:g} m/s^2 (as on the topic)'
        if name == 'weights' and values:
            low, high = WEIGHT_RANGE
            if not all(low <= v <= high for v in values):
                return f'{name}: every entry must be in [{low:g}, {high:g}]'
            if max(values) > MAX_WEIGHT_RATIO * min(values):
                return (f'{name}: the largest entry may be at most {MAX_WEIGHT_RATIO:g} times '
                        f'the smallest, got {max(values) / min(values):.3g}')
        return ''
    if isinstance(value, float) and not math.isfinite(value):
        return f'{name}: must be finite'
    if spec.low is not None and not (spec.low <= value <= spec.high):
        return f'{name}: must be in [{spec.low}, {spec.high}], got {value}'
    return ''


def wait_for_urdf(node: Node, topic: str, timeout: float,
                  stop: Callable[[], bool] = lambda: False) -> str:
    """
    Take the URDF from a robot_description topic, waiting for it up to ``timeout``.

    The subscription is reliable and transient local, as robot_state_publisher
    publishes it, so a URDF published before the node started arrives too. The
    message is taken serialized and refused by its length before it is deserialized.
    It polls (every 20 ms) instead of spinning, so it also works from inside a
    callback of the node's executor (the managed node's configure), which it then
    holds for at most ``timeout``.

    Args:
        node: the node that subscribes (for as long as this waits).
        topic: the topic (relative names resolve in the node's namespace).
        timeout: how long to wait [s].
        stop: polled; True ends the wait (a stop signal).

    Returns:
        The URDF document.

    Raises:
        InputError: nothing arrived in time, or the message is larger than a URDF may be
            (field ``robot_description_topic``).
    """
    sub = node.create_subscription(String, topic, lambda _: None, URDF_QOS, raw=True)
    name = sub.topic_name
    end = time.monotonic() + timeout
    try:
        while True:
            with sub.handle:
                taken = sub.handle.take_message(String, True)
            if taken is not None:
                data = taken[0]
                if len(data) > MAX_URDF_BYTES + URDF_MESSAGE_OVERHEAD:
                    raise InputError('robot_description_topic', f'the URDF on {name} is '
                                     f'{len(data)} bytes serialized, larger than a URDF may '
                                     f'be ({MAX_URDF_BYTES} bytes)')
                return deserialize_message(data, String).data
            if stop():
                raise InputError('robot_description_topic', f'stopped while waiting for the '
                                 f'URDF on {name}')
            if time.monotonic() >= end:
                raise InputError('robot_description_topic', f'no URDF on {name} within '
                                 f'{timeout:g} s (robot_description_timeout); it is taken '
                                 'reliable and transient local, as robot_state_publisher '
                                 'publishes it')
            time.sleep(0.02)
    finally:
        node.destroy_subscription(sub)


class GraspTorqueCore:
    """
    What the plain and the managed node share: a mixin put before rclpy's node class.

    The grasp (scenario, URDF, name map), the parameters' checks and their effect,
    the inputs, the cycle, the outputs and the ``~/solve`` service. :attr:`commanding`
    says whether the node commands now: the plain node always, the managed node
    while active. The subclass calls :meth:`_init_core` first.
    """

    def _init_core(self, message_info: bool) -> None:
        """Set the state every method relies on; nothing is loaded yet."""
        self._lock = threading.Lock()
        self._last_stamp = None  # header stamp of the last accepted joint state
        self._message_info = message_info
        self.controller: TorqueController | None = None
        self._service_controller: TorqueController | None = None
        self._scenario: Scenario | None = None
        self._base_setup: GraspSetup | None = None
        self._m: int | None = None
        self._torque_bounds: np.ndarray | None = None
        self._base_joints: list[str] | None = None
        self._filling = False  # the managed node fills in scenario defaults
        self._made: list[tuple[str, Any]] = []  # (kind, entity) made by _start_interfaces
        self._worker: ThreadPoolExecutor | None = None
        self._command_pub = None
        self._stamped_pub = None
        self._tf: tuple[Any, ...] | None = None  # (buffer, listener, node, executor, thread)
        self._pending_solves = 0
        self._busy_answers = 0
        self._duplicates = 0
        self._peers = PeerWatch()  # what _start_interfaces made, checked against the graph

    @property
    def commanding(self) -> bool:
        """Whether the node publishes commands now."""
        return self.controller is not None

    def _value(self, name: str) -> Any:
        """Give a parameter's value, None while it has none (declared by type only)."""
        try:
            return self.get_parameter(name).value
        except (ParameterUninitializedException, ParameterNotDeclaredException):
            return None  # (or, in the managed node's cleanup, being declared again)

    # -- the grasp --------------------------------------------------------------------------

    def _urdf(self, stop: Callable[[], bool] = lambda: False) -> str:
        """
        Give the URDF document to use: '' for the scenario's ``hand.urdf``.

        ``robot_description`` (a document or a path) wins; else, with
        ``robot_description_topic`` set, the URDF published there (waited for up to
        ``robot_description_timeout``); else the scenario's.
        """
        urdf = self._value('robot_description') or ''
        topic = self._value('robot_description_topic') or ''
        if urdf:
            if topic:
                self.get_logger().info(f'robot_description is set: the URDF on {topic} is '
                                       'not read')
            if not urdf.lstrip().startswith('<'):
                path = find_config(urdf, 'robot_description')
                urdf = decode_utf8(read_bounded(path, 'robot_description', MAX_URDF_BYTES),
                                   path, 'robot_description')
            return urdf
        if topic:
            reason = self._check('robot_description_topic', topic)
            if reason:
                raise InputError('robot_description_topic', reason.partition(': ')[2])
            timeout = self._value('robot_description_timeout')
            self.get_logger().info(f'waiting for the URDF on {topic} (up to {timeout:g} s)')
            return wait_for_urdf(self, topic, timeout, stop)
        return ''

    def _bind(self, urdf: str, joints: list[str] | None = None) -> GraspSetup:
        """
        Load the scenario, map its names (``name_map``) and bind it to the hand.

        Args:
            urdf: the URDF document ('' for the scenario's ``hand.urdf``).
            joints: actuated joints in command order instead of the scenario's (URDF
                names), or None.

        Raises:
            InputError: naming the parameter or the scenario's field.
        """
        name = self._value('scenario')
        if not name:
            raise InputError('scenario', 'parameter not set (a scenario file gives the '
                             'default contacts and load)')
        name_map = name_map_of(self._value('name_map'))
        scenario = self._scenario = load_scenario(find_config(name), name_map)
        if joints is not None:
            scenario = dataclasses.replace(scenario, joints=list(joints))
        try:
            return GraspSetup.from_scenario(scenario, urdf or None)
        except (JointNotFound, FrameNotFound) as e:
            if not urdf:
                raise
            raise InputError(e.field, f'{e.problem}; if the scenario names them as another '
                             "URDF of this hand does, map them to this URDF's names with the "
                             'name_map parameter (SCENARIO_NAME=URDF_NAME) or the '
                             "scenario's hand.name_map") from e

    @staticmethod
    def _load_of_gravity(scenario: Scenario) -> Callable[[np.ndarray], np.ndarray] | None:
        """
        Give the scenario's load as a function of gravity [m/s^2], or None.

        Only when the scenario's load is its object's weight (``object`` and
        ``gravity`` both given): then it is ``load.external_wrench`` plus the weight
        under the gravity given, about the scenario's object origin, base axes.
        Otherwise the load does not depend on gravity.
        """
        if scenario.object is None or scenario.gravity is None:
            return None
        obj, origin = scenario.object, scenario.object_origin.copy()
        extra = scenario.extra_wrench.copy()
        return lambda g: extra + weight_wrench(obj, np.asarray(g, dtype=float), origin)

    def _build(self, setup: GraspSetup) -> None:
        """
        Check every parameter against the hand, then make the two controllers.

        Raises:
            InputError: the first parameter refused, named.
        """
        self._m = setup.hand.m
        self._base_joints = list(setup.hand.joints)
        self._torque_bounds = self._limit_bounds(
            setup.hand, bool(self._value('torque_limits_above_urdf')))
        for name in PARAMETERS:
            reason = self._check(name, self._value(name))
            if reason:
                field, _, problem = reason.partition(': ')
                raise InputError(field, problem)
        self._base_setup = setup
        p = self._params()
        backend, warm = p['solver.backend'], p['solver.warm_start']
        fallback = _fallback(backend, p['solver.fallback'])
        self._warn_missing_fallback()
        controller = TorqueController(*self._configure(setup, p), backend, warm, fallback)
        # The service solves snapshots out of sequence: always cold.
        service = TorqueController(*self._configure(
            dataclasses.replace(setup, hand=dataclasses.replace(setup.hand)), p),
            backend, False, fallback)
        service.solver = make_solver(backend, service.solver.settings, False, SERVICE_SLICE_S)
        controller.load_of_gravity = service.load_of_gravity = \
            self._load_of_gravity(self._scenario)
        self.controller, self._service_controller = controller, service

    def _cycle_kind(self) -> str:
        """Say which cycle runs: compiled, or Python and why."""
        ctrl = self.controller
        if not ctrl.config.compiled:
            return 'Python (solver.compiled false)'
        why = compiled.unsupported(ctrl.setup, ctrl.config.method, ctrl.solver)
        return f'Python ({why})' if why else 'compiled'

    def _release(self) -> None:
        """Drop the controllers and the model (the managed node's cleanup)."""
        self.controller = self._service_controller = None
        self._base_setup = self._scenario = None
        self._m = self._torque_bounds = self._base_joints = None
        self._last_stamp = None

    # -- interfaces -------------------------------------------------------------------------

    def _make_publisher(self, msg_type: type, topic: str, qos: QoSProfile) -> Any:
        """Make a command publisher (the managed node's are lifecycle publishers)."""
        return self.create_publisher(msg_type, topic, qos, event_callbacks=quiet_publisher())

    def _start_interfaces(self) -> None:
        """Make the subscriptions, publishers, the service, the timers and the worker."""
        made = self._made
        # Serialized (raw): a message is measured before it is deserialized. With message
        # info, inputs are aged from when the middleware received them.
        for msg_type, topic, take in ((JointState, 'joint_states', self._on_joint_state),
                                      (PoseArray, 'contacts', self._on_contacts),
                                      (WrenchStamped, 'external_wrench', self._on_wrench),
                                      (Vector3Stamped, 'gravity', self._on_gravity)):
            def callback(data, info=None, msg_type=msg_type, topic=topic, take=take):
                self._on_serialized(topic, msg_type, data, take, info)
            if self._message_info:
                sub_callback = (lambda cb: lambda data, info: cb(data, info))(callback)
            else:
                sub_callback = (lambda cb: lambda data: cb(data))(callback)
            qos = JOINT_STATE_QOS if topic == 'joint_states' else qos_profile_sensor_data
            sub = self.create_subscription(msg_type, topic, sub_callback, qos, raw=True,
                                           event_callbacks=quiet_subscription())
            made.append(('subscription', sub))
            self._peers.watch(sub, msg_type)
            if topic == 'joint_states':
                self._joint_states_topic = sub.topic_name  # remapped and resolved
        self._command_pub = self._make_publisher(Float64MultiArray, 'effort_commands',
                                                 COMMAND_QOS)
        made.append(('command_publisher', self._command_pub))
        self._peers.watch(self._command_pub, Float64MultiArray)
        self._stamped_pub = None
        if self.get_parameter('publish_stamped_command').value:
            self._stamped_pub = self._make_publisher(JointState, '~/effort_commands_stamped',
                                                     COMMAND_QOS)
            made.append(('command_publisher', self._stamped_pub))
            self._peers.watch(self._stamped_pub, JointState)
        self._marker_pub = self.create_publisher(MarkerArray, '~/contact_wrenches', 1,
                                                 event_callbacks=quiet_publisher())
        self._diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', 10,
                                               event_callbacks=quiet_publisher())
        made += [('publisher', self._marker_pub), ('publisher', self._diag_pub)]
        self._peers.watch(self._marker_pub, MarkerArray)
        self._peers.watch(self._diag_pub, DiagnosticArray)
        for period, callback in (('watchdog_period', self._on_watchdog),
                                 ('diagnostics_period', self._on_diagnostics),
                                 ('marker_period', self._on_markers)):
            made.append(('timer', self.create_timer(self.get_parameter(period).value,
                                                    callback)))
        self._start_tf()

    def _start_service(self) -> None:
        """
        Make ``~/solve`` and its worker thread, for the node's lifetime.

        The managed node keeps them while unconfigured too (answering that it cannot
        solve): a request still being solved at cleanup is answered on a service that
        still exists (rclpy's executor raises out of spin when a coroutine answers on a
        destroyed one).
        """
        # The service solves in a worker thread while the executor goes on with the loop.
        # Its thread starts from the executor's, maybe SCHED_FIFO: it goes back to normal.
        self._worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix='solve_service',
                                          initializer=realtime.normal_scheduling)
        self._pending_solves = 0
        # A group of its own: in the node's default (mutually exclusive) group, each call
        # held every callback of the node, the control loop's included, until its solve
        # was done; reentrant, so that requests are taken (and answered "busy") meanwhile.
        self.create_service(Trigger, '~/solve', self._on_solve, qos_profile=SERVICE_QOS,
                            callback_group=ReentrantCallbackGroup())

    def _stop_interfaces(self) -> None:
        """Destroy what :meth:`_start_interfaces` made."""
        self._stop_tf()
        for kind, entity in reversed(self._made):
            if kind == 'subscription':
                self.destroy_subscription(entity)
            elif kind == 'command_publisher':
                self._destroy_command_publisher(entity)
            elif kind == 'publisher':
                self.destroy_publisher(entity)
            else:
                self.destroy_timer(entity)
        self._made.clear()
        self._peers.clear()
        self._command_pub = self._stamped_pub = None

    def _destroy_command_publisher(self, publisher: Any) -> None:
        self.destroy_publisher(publisher)

    def _start_tf(self) -> None:
        """
        Listen to tf2 when tf2_ros is importable, to turn gravity into base axes.

        Its listener has a node and an executor thread of its own, in this node's
        context, so that /tf traffic never waits behind the control loop (nor holds
        it). Not tested here: tf2_ros is not on the package registry.
        """
        if importlib.util.find_spec('tf2_ros') is None:
            return
        import tf2_ros

        tf_node = rclpy.create_node(f'{self.get_name()}_tf_listener',
                                    namespace=self.get_namespace(), context=self.context,
                                    start_parameter_services=False)
        buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(buffer, tf_node, spin_thread=False)
        executor = SingleThreadedExecutor(context=self.context)
        executor.add_node(tf_node)
        thread = threading.Thread(target=self._spin_tf, args=(executor,), daemon=True,
                                  name='tf_listener')
        thread.start()
        self._tf = (buffer, listener, tf_node, executor, thread)

    @staticmethod
    def _spin_tf(executor: SingleThreadedExecutor) -> None:
        realtime.normal_scheduling()  # started by the managed node's (maybe SCHED_FIFO) thread
        try:
            executor.spin()
        except ExternalShutdownException:
            pass

    def _stop_tf(self) -> None:
        if self._tf is None:
            return
        _, listener, tf_node, executor, thread = self._tf
        self._tf = None
        executor.shutdown(timeout_sec=1.0)
        thread.join(timeout=1.0)
        listener.unregister()
        tf_node.destroy_node()

    def _gravity_rotation(self, frame: str) -> tuple[np.ndarray | None, str]:
        """
        Give the base-from-``frame`` rotation from tf2 (latest), or None and why not.

        Not tested here: tf2_ros is not on the package registry.
        """
        if self._tf is None:
            return None, 'tf2_ros is not installed'
        import tf2_ros

        base = self.controller.setup.hand.base_frame
        try:
            t = self._tf[0].lookup_transform(base, frame, Time())
        except tf2_ros.TransformException as e:
            return None, f'tf2: {cut(str(e))}'
        r = t.transform.rotation
        try:
            return quaternion_matrix(np.array([r.x, r.y, r.z, r.w]),
                                     'gravity.header.frame_id transform'), ''
        except InputError as e:
            return None, f'tf2: {e}'

    # -- configuration --------------------------------------------------------------------

    @staticmethod
    def _limit_bounds(hand: Hand, above_urdf: bool) -> np.ndarray:
        """
        Give the largest torque limit per joint [N m].

        The URDF's effort limit, the scenario's limit where the URDF gives none;
        MAX_TORQUE_LIMIT if allowed above.
        """
        if above_urdf:
            return np.full(hand.m, MAX_TORQUE_LIMIT)
        effort = hand.effort_limits
        return np.where(np.isfinite(effort), effort, hand.torque_limits)

    def _check(self, name: str, value: Any) -> str:
        return check(name, value, self._m, self._torque_bounds, self._base_joints)

    def _params(self) -> dict[str, Any]:
        return {name: self._value(name) for name in PARAMETERS}

    def _configure(self, setup: GraspSetup, p: dict[str, Any]
                   ) -> tuple[GraspSetup, CycleConfig, ProxSuiteSettings]:
        """Make the controller's setup, cycle and solver settings from parameter values."""
        hand = setup.hand
        if not np.array_equal(hand.torque_limits, p['torque_limits']):
            hand = dataclasses.replace(hand, torque_limits=np.array(p['torque_limits']))
        setup = dataclasses.replace(
            setup, hand=hand, object_origin=np.array(p['object_origin']),
            weights=np.array(p['weights']), objective=p['objective'],
            friction=dataclasses.replace(setup.friction, mu1=p['mu_tangential'],
                                         mu2=p['mu_torsional'], sides=p['polygon_sides'],
                                         min_normal_force=p['min_normal_force'],
                                         margin=p['friction_margin']))
        config = CycleConfig(
            joint_state_timeout=p['joint_state_timeout'],
            contacts_timeout=p['contacts_timeout'], wrench_timeout=p['wrench_timeout'],
            hold_time=p['hold_time'], fault_policy=p['fault_policy'],
            gravity_compensation=p['gravity_compensation'], gravity=tuple(p['gravity']),
            certificate_tolerance=p['certificate_tolerance'],
            max_joint_state_entries=p['max_joint_state_entries'],
            max_message_bytes=p['max_message_bytes'],
            max_wrench_force=p['max_wrench_force'], max_wrench_torque=p['max_wrench_torque'],
            max_contact_distance=p['max_contact_distance'],
            stamp_future_tolerance=p['stamp_future_tolerance'],
            cycle_budget=p['cycle_budget'], method=p['solver.method'],
            gravity_timeout=p['gravity_timeout'], compiled=p['solver.compiled'])
        solver = ProxSuiteSettings(eps_abs=p['solver.eps_abs'], max_iter=p['solver.max_iter'],
                                   max_iter_in=p['solver.max_iter_in'])
        return setup, config, solver

    def _fixed(self, name: str) -> str:
        """Say why a parameter cannot change now ('' if it can): the managed node's rule."""
        return ''

    def _validate_parameters(self, params: list[Parameter]) -> SetParametersResult:
        for param in params:
            if param.name in PARAMETERS:
                if param.value is None:  # declared by type only (the managed node)
                    continue
                reason = self._fixed(param.name) or self._check(param.name, param.value)
                if reason:
                    return SetParametersResult(successful=False, reason=reason)
        # min-max is the tau-QP's objective only (docs/planner.md): refuse the pair.
        new = {param.name: param.value for param in params}
        objective = new.get('objective', self._value('objective'))
        method = new.get('solver.method', self._value('solver.method'))
        if objective == 'min-max' and method != 'tau-qp':
            return SetParametersResult(successful=False, reason=(
                f'objective: min-max needs solver.method tau-qp, not {method}'))
        return SetParametersResult(successful=True)

    def _apply_parameters(self, params: list[Parameter]) -> None:
        if self.controller is None or self._filling:
            return  # nothing loaded yet: configure takes the values
        p = self._params()
        with self._lock:
            warm_loop = p['solver.warm_start'] and p['solver.backend'] != 'quadprog'
            for ctrl, warm, slice_s in ((self.controller, warm_loop, None),
                                        (self._service_controller, False, SERVICE_SLICE_S)):
                setup, config, solver = self._configure(ctrl.setup, p)
                ctrl.setup, ctrl.config = setup, config
                if solver != ctrl.solver.settings or \
                        p['solver.backend'] != getattr(ctrl.solver, 'name', None) or \
                        warm != getattr(ctrl.solver, 'warm_start', False):
                    ctrl.solver = make_solver(p['solver.backend'], solver, warm, slice_s)
                fallback = _fallback(p['solver.backend'], p['solver.fallback'])
                if ctrl is self.controller and any(x.name == 'solver.fallback' for x in params):
                    self._warn_missing_fallback()
                if fallback != getattr(ctrl.fallback, 'name', None) or \
                        (ctrl.fallback is not None and ctrl.fallback.settings != solver):
                    ctrl.fallback = make_solver(fallback, solver) if fallback else None
            # The change acts on the command in force at once (a new certified command,
            # or zeros if the one in force is now over the limits), not at the next cycle.
            # Not while the managed node is inactive: it commands nothing then, and its
            # activation runs the same rule.
            if self.commanding:
                result = self.controller.reconfigured(time.monotonic())
                if result is not None:
                    self._publish(result, self._last_stamp)

    def _warn_missing_fallback(self) -> None:
        name = self.get_parameter('solver.fallback').value
        if name != 'none' and not available(name):
            self.get_logger().warning(f'solver.fallback: {name} is not installed (pip install '
                                      f'{name}); running without a fallback backend')

    # -- inputs and cycle -----------------------------------------------------------------

    def _clock_now(self) -> float:
        """Now on the node's clock (ROS time), the clock of header stamps [s]."""
        return self.get_clock().now().nanoseconds * 1e-9

    def _on_serialized(self, topic: str, msg_type: type, data: bytes, take: Any,
                       info: dict | None) -> None:
        """
        Take a message as the middleware delivered it.

        Its length is checked, then it is deserialized and taken (``take(msg, receipt)``).
        """
        receipt = received(info) if info is not None else None
        with self._lock:
            if self.controller is None:
                return  # released (the managed node's cleanup) while it waited
            try:
                self.controller.check_bytes(topic, len(data))
            except InputError as e:
                self.get_logger().warn(f'rejected: {e}', throttle_duration_sec=1.0)
                return
        take(deserialize_message(data, msg_type), receipt)

    def _on_joint_state(self, msg: JointState, receipt: float | None = None) -> None:
        """
        Take a joint state and, while the node commands, run one cycle on it.

        Args:
            msg: the joint state.
            receipt: when the middleware received it (monotonic [s]; None: now).
        """
        now = time.monotonic()
        receipt = now if receipt is None else receipt
        stamp = stamp_seconds(msg.header.stamp.sec, msg.header.stamp.nanosec)
        with self._lock:
            try:
                # Sizes first: an oversized message is not even copied.
                self.controller.check_size('joint_states',
                                           max(len(msg.name), len(msg.position)))
                self.controller.update_joint_state(list(msg.name), list(msg.position),
                                                   receipt, stamp, self._clock_now())
            except InputError as e:
                self.get_logger().warn(f'rejected: {e}', throttle_duration_sec=1.0)
                return
            self._last_stamp = msg.header.stamp
            if self.commanding:
                self._publish(self.controller.cycle(now), msg.header.stamp)

    def _on_contacts(self, msg: PoseArray, receipt: float | None = None) -> None:
        now = time.monotonic() if receipt is None else receipt
        stamp = stamp_seconds(msg.header.stamp.sec, msg.header.stamp.nanosec)
        with self._lock:
            try:
                self.controller.check_size('contacts', len(msg.poses))
                positions = [[p.position.x, p.position.y, p.position.z] for p in msg.poses]
                quats = [[p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w]
                         for p in msg.poses]
                self.controller.update_contacts(msg.header.frame_id, np.array(positions),
                                                np.array(quats), now, stamp, self._clock_now())
            except InputError as e:
                self.get_logger().warn(f'rejected: {e}', throttle_duration_sec=1.0)

    def _on_wrench(self, msg: WrenchStamped, receipt: float | None = None) -> None:
        now = time.monotonic() if receipt is None else receipt
        stamp = stamp_seconds(msg.header.stamp.sec, msg.header.stamp.nanosec)
        f, t = msg.wrench.force, msg.wrench.torque
        with self._lock:
            try:
                self.controller.update_wrench(msg.header.frame_id, [f.x, f.y, f.z],
                                              [t.x, t.y, t.z], now, stamp, self._clock_now())
            except InputError as e:
                self.get_logger().warn(f'rejected: {e}', throttle_duration_sec=1.0)

    def _on_gravity(self, msg: Vector3Stamped, receipt: float | None = None) -> None:
        """
        Take gravity [m/s^2] in the hand's base frame (another frame only through tf2).

        g(q) and the scenario's load (its object's weight) follow it; once one has
        arrived, it goes stale after ``gravity_timeout``, as the other inputs do.
        """
        now = time.monotonic() if receipt is None else receipt
        stamp = stamp_seconds(msg.header.stamp.sec, msg.header.stamp.nanosec)
        frame, v = msg.header.frame_id, msg.vector
        with self._lock:
            base = self.controller.setup.hand.base_frame
        rotation, why = (None, 'tf2_ros is not installed')
        if frame not in ('', base) and self._tf is not None:
            rotation, why = self._gravity_rotation(frame)
        with self._lock:
            try:
                self.controller.update_gravity(frame, [v.x, v.y, v.z], now, stamp,
                                               self._clock_now(), rotation, why)
            except InputError as e:
                self.get_logger().warn(f'rejected: {e}', throttle_duration_sec=1.0)

    def _on_watchdog(self) -> None:
        if not self.commanding:
            return
        with self._lock:
            result = self.controller.watchdog(time.monotonic())
            if result is not None:
                self._publish(result)

    def _publish(self, result: CycleResult, stamp: Any = None) -> None:
        if result.fault:
            self.get_logger().warn(f'no command: {result.fault}', throttle_duration_sec=1.0)
        if result.command is None:
            return
        cmd = result.command
        # The node's own promise, whatever the controller decided.
        if cmd.shape != (self._m,) or not np.all(np.isfinite(cmd)) or \
                np.any(np.abs(cmd) > self.controller.setup.hand.torque_limits):
            self.get_logger().error('refused to publish a malformed command')
            return
        data = [float(x) for x in cmd]
        self._command_pub.publish(Float64MultiArray(data=data))
        if self._stamped_pub is not None:
            msg = JointState(name=list(self.controller.setup.hand.joints), effort=data)
            msg.header.stamp = stamp if stamp is not None else self.get_clock().now().to_msg()
            msg.header.frame_id = self.controller.setup.hand.base_frame
            self._stamped_pub.publish(msg)

    # -- other nodes of this name -------------------------------------------------------

    def duplicates(self) -> int:
        """Count the other nodes of this node's name and namespace that the graph shows."""
        me = (self.get_name(), self.get_namespace())
        return sum(1 for n in self.get_node_names_and_namespaces() if tuple(n) == me) - 1

    def wait_for_duplicates(self, seconds: float) -> int:
        """
        Look for other nodes of this name for up to ``seconds``.

        Discovery took 0.2 to 2.8 s here. Nothing spins meanwhile: nothing is taken or
        published.

        Returns:
            How many were seen (0 after ``seconds``).
        """
        end = time.monotonic() + seconds
        while True:
            n = self.duplicates()
            if n > 0 or time.monotonic() >= end:
                return n
            time.sleep(0.05)

    # -- outputs between cycles -----------------------------------------------------------

    def _state_note(self) -> str:
        """Say why the node does not command although configured ('' when it does)."""
        return ''

    def _on_diagnostics(self) -> None:
        with self._lock:
            now = time.monotonic()
            rep = diagnostics.report(self.controller, now)
            gravity_time = self.controller.inputs.gravity_time
            # The hand's name from its URDF (e.g. allegro_hand_right), as hardware_id asks.
            hand = self.controller.setup.hand.model.name
        # Two sources of joint states are followed as one stream (the stamp rule keeps
        # either from locking the other out); say so, as the node cannot tell them apart.
        publishers = self.count_publishers(self._joint_states_topic)
        if publishers > 1:
            self.get_logger().warn(f'{publishers} publishers on {self._joint_states_topic}: '
                                   'their joint states are taken as one stream',
                                   throttle_duration_sec=10.0)
        values = [*rep.values, ('joint_states.publishers', str(publishers)),
                  ('age.gravity_s', 'never' if gravity_time is None
                   else f'{now - gravity_time:.4f}')]
        if not any(k == 'rejected.gravity' for k, _ in values):
            values.append(('rejected.gravity', '0'))  # counted from its first rejection
        level, message = rep.level, rep.message
        note = self._state_note()
        if note:
            level, message = diagnostics.STALE, f'{note}; {message}'
        self._duplicates = self.duplicates()  # about 1 us: rmw's graph cache
        if self._duplicates > 0:
            name = self.get_fully_qualified_name()
            self.get_logger().error(f'another node named {name} is on this domain: both may '
                                    'drive effort_commands and take parameters',
                                    throttle_duration_sec=10.0)
            level = diagnostics.ERROR
            message = f'another node named {name} is on this domain; {message}'
        values.append(('duplicate_nodes', str(self._duplicates)))
        values.append(('executor_thread', realtime.describe()))  # this callback's thread
        # What rclpy's default QoS event handlers would have logged, found from the graph.
        peers, new = self._peers.check(self)
        for peer in new:
            self.get_logger().warn(f'{peer.describe()}: no messages will pass between it '
                                   'and this node')
        values.append(('incompatible_peers', summary(peers)))
        if peers:
            level = max(level, diagnostics.WARN)  # at least WARN (STALE and ERROR stay)
            message = f'{len(peers)} incompatible peer(s) on its topics; {message}'
        status = DiagnosticStatus(level=bytes([level]), name=f'{self.get_name()}: grasp '
                                  'torques', message=message, hardware_id=hand,
                                  values=[KeyValue(key=k, value=v) for k, v in values])
        msg = DiagnosticArray(status=[status])
        msg.header.stamp = self.get_clock().now().to_msg()
        self._diag_pub.publish(msg)

    def _on_markers(self) -> None:
        with self._lock:
            last = self.controller.last if self.commanding else None
            base = self.controller.setup.hand.base_frame
        self._marker_pub.publish(self._markers(last, base, self.get_clock().now().to_msg()))

    def _markers(self, last: CycleResult | None, base: str, stamp) -> MarkerArray:
        clear = Marker(action=Marker.DELETEALL)
        if last is None or last.kind != 'solution':
            return MarkerArray(markers=[clear])
        scale = self.get_parameter('marker_scale').value
        markers = [clear]
        for i, (frame, w) in enumerate(zip(last.maps.contacts, last.solution.wrenches)):
            force = frame.rotation @ w[:3]
            start, end = frame.position, frame.position + scale * force
            m = Marker(type=Marker.ARROW, action=Marker.ADD, ns='contact_force', id=i)
            m.header.frame_id, m.header.stamp = base, stamp
            m.points = [Point(x=float(start[0]), y=float(start[1]), z=float(start[2])),
                        Point(x=float(end[0]), y=float(end[1]), z=float(end[2]))]
            m.pose.orientation.w = 1.0
            m.scale.x, m.scale.y, m.scale.z = 0.002, 0.004, 0.004
            m.color.g, m.color.a = 0.8, 1.0
            m.lifetime = Duration(seconds=3 * self.get_parameter('marker_period').value).to_msg()
            markers.append(m)
        return MarkerArray(markers=markers)

    # -- the service ----------------------------------------------------------------------

    async def _on_solve(self, request: Trigger.Request, response: Trigger.Response
                        ) -> Trigger.Response:
        """
        Queue one solve for the worker, or answer "busy" at once.

        "busy" when MAX_PENDING_SOLVES are queued: every request gets an answer, in
        bounded memory. Runs in the executor's thread only, as does the count.
        """
        if self._pending_solves >= MAX_PENDING_SOLVES:
            self._busy_answers += 1
            response.success = False
            response.message = (f'busy: {self._pending_solves} solves queued (at most '
                                f'{MAX_PENDING_SOLVES}); call again later')
            return response
        with self._lock:
            worker, ctrl = self._worker, self._service_controller
            inputs = self.controller.inputs if self.controller is not None else None
        if worker is None or ctrl is None:
            response.success = False
            response.message = 'cannot solve: not configured (lifecycle state unconfigured)'
            return response
        self._pending_solves += 1
        try:
            done = Future(executor=self.executor)
            done.add_done_callback(lambda _: None)  # completion wakes the executor
            worker.submit(self._solve_for_service, inputs, time.monotonic(), done, ctrl)
            await done
        finally:
            self._pending_solves -= 1
        response.success, response.message = done.result()
        return response

    def _solve_for_service(self, inputs: Any, now: float, done: Future,
                           ctrl: TorqueController | None = None) -> None:
        """
        Solve once on a snapshot of the inputs, with the service's own controller.

        It has its own Pinocchio data and ProxSuite workspace (``ctrl``, taken when the
        request came: None for the node's current one). ``done`` gets (success, the
        CLI's JSON or the reason).
        """
        ctrl = self._service_controller if ctrl is None else ctrl
        try:
            stale = ctrl.stale(now, inputs)
            if stale:
                done.set_result((False, f'cannot solve: {stale}'))
                return
            sol, maps, g = ctrl.solve_inputs(inputs, time.perf_counter() + ctrl.budget())
            cmd, _ = ctrl.gate(sol, g)
            if sol.status == 'infeasible':  # what can be held, and what binds (docs/planner.md)
                from grasp_torque_opt.methods.explain import explain

                sol.infeasibility = explain(ctrl.grasp_at(inputs)[0], maps).as_dict()
            d = solution_dict(sol, maps)
            d['command'] = None if cmd is None else [float(x) for x in cmd]
            d['gravity_torque'] = None if g is None else [float(x) for x in g]
            done.set_result((cmd is not None, strict_json(d)))
        except Exception as e:  # noqa: BLE001 -- the caller gets the reason, the node lives on
            done.set_result((False, f'cannot solve: {type(e).__name__}: {e}'))

    def safe_stop(self) -> bool:
        """
        Take the safe action when the node stops commanding, per ``fault_policy``.

        ``zero``: publish zero torques once and wait (up to 0.5 s) for the
        subscribers to acknowledge them, since the effort controller would keep
        the last command forever. ``hold``: nothing (the last certified command
        stays, as during a fault). Nothing either before the first command, nor
        while the node does not command (the managed node took it on deactivate).

        Returns:
            True if zero torques were published.
        """
        with self._lock:
            if not self.commanding or self.controller.config.fault_policy != 'zero' or \
                    self.controller.counters.commands == 0 or not self.context.ok():
                return False
            self._command_pub.publish(Float64MultiArray(data=[0.0] * self._m))
            self.controller.in_force = np.zeros(self._m)  # what the effort controller holds
        self._command_pub.wait_for_all_acked(Duration(seconds=0.5))
        self.get_logger().info('stopped: zero torques published (fault_policy zero)')
        return True


class GraspTorqueNode(GraspTorqueCore, Node):
    """Publishes certified effort commands on each joint state; answers ``~/solve``."""

    def __init__(self, message_info: bool = True, **kwargs: Any) -> None:
        """
        Load the scenario and the hand, declare the parameters, start the interfaces.

        Args:
            message_info: age inputs from the middleware's receipt time (rmw message
                info); False: from the callback's time (rclpy 7.1's EventsExecutor
                raises SystemError on subscriptions that take message info).
            kwargs: for rclpy's Node (context, parameter_overrides, ...).

        Raises:
            InputError: a parameter, the scenario or the URDF is refused (named).
        """
        super().__init__(NODE_NAME, **kwargs)
        self._init_core(message_info)
        fixed = fixed_defaults()
        for name in ('scenario', 'robot_description', 'robot_description_topic',
                     'robot_description_timeout'):
            self.declare_parameter(name, fixed.pop(name), descriptor(name))
        self.declare_parameter('name_map', Parameter.Type.STRING_ARRAY, descriptor('name_map'))
        reason = self._check('name_map', self._value('name_map'))
        if reason:
            field, _, problem = reason.partition(': ')
            raise InputError(field, problem)
        urdf = self._urdf(stop_requested)
        setup = self._bind(urdf)
        defaults = scenario_defaults(self._scenario, setup)
        joints = self.declare_parameter('joints', defaults.pop('joints'),
                                        descriptor('joints')).value
        if list(joints) != list(setup.hand.joints):
            setup = self._bind(urdf, list(joints))
            defaults = {k: v for k, v in scenario_defaults(self._scenario, setup).items()
                        if k != 'joints'}
        for name in PARAMETERS:
            if name in defaults or name in fixed:
                value = defaults[name] if name in defaults else fixed[name]
                self.declare_parameter(name, value, descriptor(name))
        self._build(setup)
        self.add_on_set_parameters_callback(self._validate_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)
        self._start_interfaces()
        self._start_service()
        self.get_logger().info(
            f"{self._m} joints in command order ({', '.join(setup.hand.joints)}), "
            f'{len(setup.contacts)} default contacts; commands on '
            f'{self._command_pub.topic_name}; cycle: {self._cycle_kind()}')

    def destroy_node(self) -> None:
        """Take the safe action, then stop the service worker and the node."""
        self.safe_stop()
        self._stop_tf()
        if self._worker is not None:
            self._worker.shutdown(wait=True, cancel_futures=True)
        super().destroy_node()


#: Signal that asked ``main`` to stop (None: none yet).
_stop_signal: int | None = None


def stop_requested() -> bool:
    """Say whether a stop signal has arrived (polled by waits that may take long)."""
    return _stop_signal is not None


def _interrupt(signum: int, frame: Any) -> None:
    """
    Ask ``main``'s spin loop to end on SIGINT/SIGTERM; the node then stops cleanly.

    Only a flag: an exception raised here would surface at whatever bytecode the main
    thread runs next -- inside rclpy's executor (between a handle's ``__enter__`` and its
    exit), inside the events executor's C++ callback loop, or inside a ``__del__``, where
    Python drops it and the node spins on. A second signal raises KeyboardInterrupt (a way
    out should the stop itself hang).
    """
    global _stop_signal
    if _stop_signal is not None:
        raise KeyboardInterrupt
    _stop_signal = signum


#: Executors ``main`` can spin: rclpy's default and its experimental events executor.
EXECUTORS = {'single': SingleThreadedExecutor, 'events': EventsExecutor}


def run(make_node: Callable[..., Node], prog: str, args: list[str] | None = None) -> int:
    """
    Run a node (Jazzy pattern): spin, then destroy and shut down.

    Besides the ROS arguments, ``--executor single|events`` picks the executor.

    Args:
        make_node: the node's class (or a factory taking ``message_info``).
        prog: the executable's name, for messages.
        args: the command line (None: ``sys.argv``).

    Returns:
        The exit code: 0, or 2 with one line on stderr when the node refuses to run.
    """
    global _stop_signal
    argv = sys.argv if args is None else args
    parser = argparse.ArgumentParser(prog=prog)
    parser.add_argument('--executor', choices=sorted(EXECUTORS), default='single',
                        help='rclpy executor to spin (default: single)')
    try:
        opts = parser.parse_args(remove_ros_args(argv)[1:])
        single_threaded_math()
        # rclpy's own handlers would shut the context down on SIGINT/SIGTERM, before the
        # safe action could publish; here both end the spin loop and the context stays
        # valid. SIGINT explicitly too: a process started from a background job inherits
        # it ignored.
        rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    except Exception as e:  # noqa: B902 -- rcl's argument errors are pybind types of rclpy's
        # e.g. a --params-file that cannot be opened: rcl parses it before any node exists.
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        print(f'{prog}: error: ROS arguments: {first}', file=sys.stderr)
        return 2
    _stop_signal = None
    previous = {sig: signal.signal(sig, _interrupt) for sig in (signal.SIGINT, signal.SIGTERM)}
    node = None
    executor = None
    code = 0
    try:
        node = make_node(message_info=opts.executor != 'events')
        wait = node.get_parameter('startup_check_time').value
        if wait > 0.0:
            node.get_logger().info(f'looking for another {NODE_NAME} on this domain ({wait:g} s)')
            if node.wait_for_duplicates(wait):
                raise GraspTorqueError(
                    f'another node named {node.get_fully_qualified_name()} is on this domain '
                    f'(ROS_DOMAIN_ID {node.context.get_domain_id()}): refusing to run, as both '
                    'would drive effort_commands (stop it, or give this one another name with '
                    '--ros-args -r __node:=NAME)')
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
        # watchdog tick at the latest. (EventsExecutor.spin() also delivered no subscription
        # callback with these wheels, rclpy 7.1.6 and Fast DDS, while keeping a core busy.)
        timeout = 1.0 if opts.executor == 'events' else None
        while _stop_signal is None and rclpy.ok():
            executor.spin_once(timeout_sec=timeout)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except GraspTorqueError as e:
        print(f'{prog}: error: {e}', file=sys.stderr)
        code = 2
    except (ParameterException, NameValidationException) as e:
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
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return code


def main(args: list[str] | None = None) -> int:
    """Run the plain node ``grasp_torque_node``, which commands from its start."""
    return run(GraspTorqueNode, NODE_NAME, args)


if __name__ == '__main__':
    sys.exit(main())
