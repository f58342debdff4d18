# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The adversarial campaign, part 1: a real node's own callbacks, and the CLI.

Generated messages, parameter changes and failing solvers go through the node's own
callbacks (no executor: every publish is seen), generated scenario files through the
CLI. Counts are printed at the end of the run.
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import io
import json
import math
import time

from campaign import as_message, broken, CAMPAIGN, check_command, COUNTS, FLOATS, mutated
from conftest import ALLEGRO, PLANAR
from cycle_inputs import base_poses, FAULT_MODES, Injected, joint_state
from geometry_msgs.msg import Pose, PoseArray, WrenchStamped
from grasp_torque_opt.cli import main as cli_main
from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.control.parameters.snapshot import cycle_config
from grasp_torque_opt.core import scenario as schema, scenario_fields as fields
from grasp_torque_opt.ros.node import controllers, GraspTorqueNode, PARAMETERS
from hypothesis import given, settings
from hypothesis import strategies as st
from independent import assert_holds
import numpy as np
import pytest
import rclpy
from rclpy.parameter import Parameter
from rclpy.task import Future
from ros_harness import DOMAIN
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray
import yaml

#: No cycle may take longer than this, whatever the input: its solvers stop by its budget
#: (at most cycle_budget's upper bound, 1 s) and overrun it by one outer iteration at most.
STALL = 1.5
#: Between the cycle's last freshness check and the publish call [s].
PUBLISH_MARGIN = 0.005


class Recorder:
    """
    Stands in front of the node's command publisher.

    It publishes for real, and keeps each command with the controller's decision it came
    from.
    """

    def __init__(self, node: GraspTorqueNode):
        self.node, self.real, self.seen = node, node.root.outputs.command_pub, []
        node.root.outputs.command_pub = self

    def publish(self, msg) -> None:
        self.real.publish(msg)
        ctrl = self.node.controller  # publish follows the cycle at once: same inputs
        # The controller as it is now (a shallow copy keeps this setup and config): a
        # parameter change after the command must not be held against it.
        data = as_message(msg, Float64MultiArray).data
        self.seen.append((np.array(data), ctrl.last, ctrl.inputs, copy.copy(ctrl),
                          time.monotonic()))

    def __getattr__(self, name: str):
        return getattr(self.real, name)  # e.g. wait_for_all_acked in the safe stop


class Rig:
    """A real node on a private domain; the campaign calls its callbacks directly."""

    def __init__(self, scenario, setup, **params):
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=DOMAIN)
        overrides = [Parameter('scenario', value=str(scenario))]
        overrides += [Parameter(k, value=v) for k, v in params.items()]
        self.node = GraspTorqueNode(context=self.context, parameter_overrides=overrides)
        values = self.node.root.parameters.values()
        # Typed as declared: an empty list's own type would be a byte array (tactile.links).
        self.defaults = [Parameter(n, self.node.get_parameter(n).type_, v)
                         for n, v in values.items() if not PARAMETERS[n].read_only]
        self.recorder = Recorder(self.node)
        self.setup = setup
        names, pos = joint_state(setup)
        self.valid_js = JointState(name=names, position=pos, effort=[math.nan] * len(names))
        self.valid_contacts = PoseArray()
        for p, q in zip(*base_poses(setup)):
            pose = Pose()
            pose.position.x, pose.position.y, pose.position.z = (float(v) for v in p)
            (pose.orientation.x, pose.orientation.y, pose.orientation.z,
             pose.orientation.w) = (float(v) for v in q)
            self.valid_contacts.poses.append(pose)
        self.valid_wrench = WrenchStamped()
        w = setup.external_wrench
        f, t = self.valid_wrench.wrench.force, self.valid_wrench.wrench.torque
        f.x, f.y, f.z, t.x, t.y, t.z = (float(v) for v in w)
        model = setup.hand.model
        self.names = names + [model.frames[i].name for i in range(0, len(model.frames), 3)]

    def reset(self) -> None:
        assert all(r.successful for r in self.node.set_parameters(self.defaults))
        root = self.node.root
        with root.lock:
            p = root.params
            root.controller = TorqueController(controllers.setup_of(root.grasp.setup, p),
                                               cycle_config(p), controllers.solver_settings(p))
        self.recorder.seen.clear()

    def close(self) -> None:
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


def operations(rig: Rig, size: int) -> st.SearchStrategy:
    """Return what can happen to a running node: messages, time, parameter changes, solvers."""
    js = mutated(rig.valid_js, rig.names)
    m = rig.setup.hand.m
    param = st.one_of(
        st.tuples(st.sampled_from(['mu_tangential', 'mu_torsional', 'min_normal_force',
                                   'hold_time', 'joint_state_timeout', 'max_wrench_force',
                                   'max_contact_distance', 'stamp_future_tolerance',
                                   'cycle_budget', 'certificate_tolerance']), FLOATS),
        st.tuples(st.sampled_from(['torque_limits', 'weights', 'object_origin', 'gravity']),
                  st.lists(FLOATS, max_size=20)),
        st.tuples(st.sampled_from(['polygon_sides', 'solver.max_iter', 'solver.max_iter_in',
                                   'max_joint_state_entries']), st.integers(-5, 300)),
        st.tuples(st.just('fault_policy'), st.sampled_from(['hold', 'zero', '', 'explode'])),
        st.tuples(st.just('gravity_compensation'), st.booleans()),
        # The issue's freeze: iteration caps, tolerance and the weights' ratio at their bounds.
        st.tuples(st.just('solver.max_iter'), st.sampled_from([10000, 10001, 100000])),
        st.tuples(st.just('solver.max_iter_in'), st.sampled_from([200, 201, 100000])),
        st.tuples(st.just('solver.eps_abs'), st.just(1e-12)),
        st.tuples(st.just('weights'), st.sampled_from(
            [[1e-3, 1e3] * (m // 2) + [1.0] * (m % 2), [1e-6] * (m - 1) + [1.0],
             [1e-12, 1e12] * (m // 2) + [1.0] * (m % 2)])),
        st.tuples(st.just('cycle_budget'), st.sampled_from([1e-4, 1.0, 10.0])))
    op = st.one_of(
        st.tuples(st.just('joint_states'), js), st.tuples(st.just('joint_states'), js),
        st.tuples(st.just('joint_states'), st.just(rig.valid_js)),
        st.tuples(st.just('contacts'), mutated(rig.valid_contacts, rig.names)),
        st.tuples(st.just('external_wrench'), mutated(rig.valid_wrench, rig.names)),
        st.tuples(st.just('sleep'), st.sampled_from([0.005, 0.02, 0.05])),
        st.tuples(st.just('watchdog'), st.none()),
        st.tuples(st.just('solver'), st.sampled_from(FAULT_MODES + ['healthy'] * 4)),
        st.tuples(st.just('param'), param),
        # Changes that make the command in force invalid: limits below it.
        st.tuples(st.just('limits_below'), st.sampled_from([0.01, 0.3, 0.9])),
        # Two sources: one stamping ahead of (or behind) the clock, one on it.
        st.tuples(st.just('skewed_joint_state'), st.sampled_from([0.4, 0.49, 0.6, -0.4])),
        st.tuples(st.just('joint_state_on_clock'), st.none()))
    return st.lists(op, min_size=1, max_size=size)


def run(rig: Rig, ops) -> None:
    """Apply the operations, then check every published command and the service."""
    rig.reset()
    node = rig.node
    for kind, arg in ops:
        COUNTS['inputs'] += 1
        t0 = time.perf_counter()
        if kind == 'joint_states':
            node.root.inputs.on_joint_state(arg)
        elif kind == 'contacts':
            node.root.inputs.on_message('contacts', arg)
        elif kind == 'external_wrench':
            node.root.inputs.on_message('external_wrench', arg)
        elif kind == 'sleep':
            time.sleep(arg)
        elif kind == 'watchdog':
            node.root.on_watchdog()
        elif kind == 'solver':
            solver = Injected(arg if arg != 'healthy' else FAULT_MODES[0])
            solver.healthy = arg == 'healthy'
            node.controller.solver = solver
        elif kind == 'limits_below':
            seen = rig.recorder.seen  # the command in force: the last one published
            ref = seen[-1][0] if seen else node.controller.setup.hand.torque_limits
            limits = np.maximum(arg * np.abs(ref), 1e-3)
            node.set_parameters([Parameter('torque_limits', value=[float(x) for x in limits])])
        elif kind in ('skewed_joint_state', 'joint_state_on_clock'):
            msg = copy.deepcopy(rig.valid_js)
            t = node.root.inputs.clock_now() + (arg or 0.0)
            msg.header.stamp.sec, msg.header.stamp.nanosec = int(t), int((t % 1.0) * 1e9)
            before = node.controller.counters.rejected['joint_states']
            node.root.inputs.on_joint_state(msg)
            refused = node.controller.counters.rejected['joint_states'] > before
            if kind == 'joint_state_on_clock' and refused and \
                    'header.stamp' in node.controller.last_rejection:
                broken(f'a joint state on the clock refused: {node.controller.last_rejection}')
        else:
            name, value = arg
            if isinstance(value, list) and name in ('torque_limits', 'weights'):
                value = [float(v) for v in value]
            try:
                node.set_parameters([Parameter(name, value=value)])
            except Exception as e:  # noqa: BLE001 -- a refused type is fine; anything else not
                assert type(e).__name__ in ('InvalidParameterTypeException',
                                            'InvalidParameterValueException'), e
        if kind != 'sleep' and time.perf_counter() - t0 > STALL:
            broken(f'{kind} took {time.perf_counter() - t0:.2f} s')
        # What the effort controller holds is within the limits in force, whatever changed.
        if rig.recorder.seen:
            held = rig.recorder.seen[-1][0]
            limits = node.controller.setup.hand.torque_limits
            if held.shape == limits.shape and np.any(np.abs(held) > limits):
                broken(f'the command in force exceeds the limits in force after {kind}')
    ctrl = node.controller
    for cmd, decision, inputs, then, sent in rig.recorder.seen:
        check_command(cmd, rig.setup.hand.m, then.setup.hand.torque_limits)
        if decision is None or decision.command is None or \
                not np.array_equal(decision.command, cmd):
            broken("a command that is not the controller's decision")
        if decision.kind == 'zero':
            if np.any(cmd != 0.0):
                broken('a zero-policy command that is not zero')
            continue
        sol = decision.solution
        if decision.kind != 'solution' or not sol.optimal or not sol.certificate.ok:
            broken(f'a command from an uncertified solution ({decision.kind})')
        if decision.cycle_time > then.config.cycle_budget:
            broken(f'a command from a cycle over budget ({decision.cycle_time:.4f} s)')
        if sent - inputs.q_time > then.config.joint_state_timeout + PUBLISH_MARGIN:
            broken(f'a command sent {sent - inputs.q_time:.4f} s after its joint state')
        # Independently of the package's certificate, at the inputs and parameters it was
        # computed from (its limits are checked on the command above).
        setup, _ = then.grasp_at(inputs)
        try:
            assert_holds(dataclasses.replace(setup, hand=dataclasses.replace(
                setup.hand, torque_limits=np.full(rig.setup.hand.m, np.inf))),
                decision.maps, sol.tau, sol.wrenches)
        except AssertionError as e:
            broken(f'a command fails the independent check: {e}')
    # The service still answers, with a certified command or a reason.
    done = Future()
    node.root.service.solve(ctrl.inputs, time.monotonic(), done)
    success, message = done.result()
    if success:
        d = json.loads(message)
        check_command(d['command'], rig.setup.hand.m, ctrl.setup.hand.torque_limits)
    elif not message.startswith('cannot solve: ') and \
            json.loads(message).get('command', 'missing') is not None:
        broken(f'service failed without a reason: {message[:200]}')


@pytest.fixture(scope='module')
def planar_rig(planar):
    rig = Rig(PLANAR, planar, joint_state_timeout=0.03, contacts_timeout=0.06,
              wrench_timeout=0.06, hold_time=0.02, fault_policy='zero')
    yield rig
    rig.close()


@pytest.fixture(scope='module')
def allegro_rig(allegro):
    rig = Rig(ALLEGRO, allegro, joint_state_timeout=0.03, hold_time=0.02,
              gravity_compensation=True, gravity=[9.81, 0.0, 0.0])
    yield rig
    rig.close()


def test_campaign_planar_node(planar_rig):
    @settings(CAMPAIGN, max_examples=150)
    @given(ops=operations(planar_rig, 14))
    def campaign(ops):
        run(planar_rig, ops)

    before = COUNTS['commands']
    campaign()
    assert COUNTS['commands'] > before  # the campaign reached the solver, not only checks


def test_campaign_allegro_node(allegro_rig):
    @settings(CAMPAIGN, max_examples=50)
    @given(ops=operations(allegro_rig, 10))
    def campaign(ops):
        run(allegro_rig, ops)

    before = COUNTS['commands']
    campaign()
    assert COUNTS['commands'] > before


# -- the CLI on generated scenario files ----------------------------------------------------


def scenario_fields(doc: dict) -> list[tuple]:
    """
    Return the paths of every field the schema allows in a scenario document, in a fixed order.

    The schema's sets iterate in an order that changes with each process's string hashes,
    which made the derandomized examples differ from run to run (and, now and then, none
    of the 120 solve).
    """
    out = [(section, key) for section, keys in sorted(schema._SECTIONS.items())
           for key in sorted(keys)]
    for i in range(len(doc['grasp']['contacts'])):
        out += [('grasp', 'contacts', i, key) for key in sorted(fields._CONTACT_KEYS)]
    return out


JUNK = st.one_of(FLOATS, st.none(), st.booleans(), st.integers(-10, 10), st.text(max_size=8),
                 st.lists(FLOATS, max_size=8), st.lists(st.text(max_size=6), max_size=4),
                 st.dictionaries(st.text(max_size=6), FLOATS, max_size=3), st.just([]))


@st.composite
def scenario_docs(draw, doc: dict):
    fields = scenario_fields(doc)
    doc = copy.deepcopy(doc)
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from(fields))
        target = doc
        for k in path[:-1]:
            if isinstance(k, str) and isinstance(target, dict):
                target = target.setdefault(k, {})
            elif isinstance(k, int) and isinstance(target, list) and k < len(target):
                target = target[k]
            else:
                target = None  # an earlier mutation replaced the parent: skip
                break
        if not isinstance(target, dict):
            continue
        old = target.get(path[-1])
        if isinstance(old, list) and old and all(isinstance(v, (int, float)) for v in old) \
                and draw(st.booleans()):
            value = list(old)
            value[draw(st.integers(0, len(value) - 1))] = draw(FLOATS)
        else:
            value = draw(JUNK)
        target[path[-1]] = value
    return doc


def test_campaign_cli(tmp_path, planar_doc):
    doc = copy.deepcopy(planar_doc)
    doc['hand']['urdf'] = str(PLANAR.parent / doc['hand']['urdf'])
    path = tmp_path / 'generated.yaml'

    codes = []

    @settings(CAMPAIGN, max_examples=120)
    @given(scenario_docs(doc))
    def campaign(d):
        COUNTS['inputs'] += 1
        path.write_text(yaml.safe_dump(d))
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = cli_main(['solve', str(path), '--json'])
        codes.append(code)
        if code == 2:
            lines = err.getvalue().splitlines()
            if len(lines) != 1 or not lines[0].startswith(f'grasp-torque-opt: error: {path}: '):
                broken(f'bad input without one line naming the field: {err.getvalue()!r}')
            return
        if code not in (0, 3, 4):
            broken(f'exit code {code}')
        r = json.loads(out.getvalue())
        if code == 0:
            check_command(r['tau'], len(r['joints']), np.full(len(r['joints']), np.inf))
            if not r['certificate']['ok'] or r['status'] != 'optimal':
                broken('exit 0 without a certified optimum')
            limits = d['hand'].get('torque_limits')
            if isinstance(limits, list) and len(limits) == len(r['tau']) and \
                    np.any(np.abs(r['tau']) > np.array(limits, dtype=float)):
                broken('a torque over its limit')
        elif r['tau'] is not None:
            broken(f'exit {code} with torques')

    campaign()
    assert {0, 2} <= set(codes)  # both solved and refused files were generated


# -- the CLI on hostile files ----------------------------------------------------------------

#: Longest a hostile file may take through the CLI [s] (the bounds make it well under 1 s).
FILE_STALL = 10.0


@st.composite
def hostile_texts(draw, text: str) -> bytes:
    """
    Draw a valid scenario's text made hostile in some field.

    The kinds: YAML aliases nested some levels deep, nesting, bytes that are not UTF-8,
    many contacts, long strings, long integers.
    """
    lines = text.splitlines()
    fields = [i for i, line in enumerate(lines) if ': ' in line and not line.endswith(':')]
    i = draw(st.sampled_from(fields))
    key = lines[i].split(': ', 1)[0]
    kind = draw(st.sampled_from(['aliases', 'nesting', 'bytes', 'contacts', 'string',
                                 'integer']))
    if kind == 'aliases':
        levels = draw(st.integers(1, 7))
        parts = ['&a0 ["lol", "lol", "lol"]'] + [
            f'&a{k} [' + ', '.join([f'*a{k - 1}'] * draw(st.integers(2, 9))) + ']'
            for k in range(1, levels)]
        lines[i] = f"{key}: [{', '.join(parts)}]"
    elif kind == 'nesting':
        depth = draw(st.integers(5, 3000))
        lines[i] = f"{key}: {'[' * depth}1{']' * depth}"
    elif kind == 'string':
        lines[i] = f"{key}: {'x' * draw(st.integers(100, 200_000))}"
    elif kind == 'integer':
        lines[i] = f"{key}: {'7' * draw(st.integers(10, 6000))}"
    elif kind == 'contacts':
        n = draw(st.integers(1, 300))
        at = next(j for j, line in enumerate(lines) if line.strip() == 'contacts:')
        first = next(j for j in range(at + 1, len(lines)) if lines[j].lstrip().startswith('- '))
        last = next((j for j in range(first + 1, len(lines))
                     if lines[j].lstrip().startswith('- ') or not lines[j].startswith('  ')),
                    len(lines))
        lines[first:first] = lines[first:last] * n
    data = '\n'.join(lines).encode() + b'\n'
    if kind == 'bytes':
        at = draw(st.integers(0, len(data)))
        data = data[:at] + draw(st.binary(min_size=1, max_size=8)) + data[at:]
    return data


def test_campaign_hostile_files(tmp_path, planar_doc):
    doc = copy.deepcopy(planar_doc)
    doc['hand']['urdf'] = str(PLANAR.parent / doc['hand']['urdf'])
    path = tmp_path / 'hostile.yaml'
    codes = []

    @settings(CAMPAIGN, max_examples=80)
    @given(hostile_texts(yaml.safe_dump(doc)))
    def campaign(data):
        COUNTS['inputs'] += 1
        path.write_bytes(data)
        out, err = io.StringIO(), io.StringIO()
        t0 = time.perf_counter()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = cli_main(['solve', str(path), '--json'])
        if time.perf_counter() - t0 > FILE_STALL:
            broken(f'a hostile file took {time.perf_counter() - t0:.1f} s')
        codes.append(code)
        if code == 2:
            lines = err.getvalue().splitlines()
            if len(lines) != 1 or not lines[0].startswith(f'grasp-torque-opt: error: {path}: ') \
                    or len(lines[0]) > 1000:
                broken(f'bad input without one short line naming it: {err.getvalue()[:300]!r}')
        elif code in (0, 3, 4):
            json.loads(out.getvalue())
        else:
            broken(f'exit code {code}')

    campaign()
    assert 2 in codes
