# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The object loop's rule on the real Allegro hand (Pinocchio), without a simulation (issue 32, 2).

The object's motion is made by moving the joints so that the contact points move as a
rigid body would (least squares through the contacts' Jacobians, as an independent
formulation of G^T dx = J dq); the loop's wrench is checked against K e + Ki integral(e)
computed here, its integral's bound, its unwinding at a torque limit and without a
certified command, its freeze while a contact slips, and the squeeze's rise and relax.
"""

from conftest import ALLEGRO
from grasp_torque_opt.control.object_loop import LIMIT_FRACTION, LoopGains, ObjectLoop
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.native import loader
import numpy as np
import pinocchio as pin
import pytest

SCENARIO = load_scenario(ALLEGRO)
SETUP = GraspSetup.from_scenario(SCENARIO)
HAND = SETUP.hand
WEIGHT = float(SCENARIO.object.mass * np.linalg.norm(SCENARIO.gravity))
ORIGIN = np.asarray(SETUP.object_origin, dtype=float)
LIMITS = HAND.torque_limits
DT = 0.004
GAINS = LoopGains(stiffness=300.0, rotational_stiffness=0.3, integral=3000.0,
                  rotational_integral=3.0, max_integral_ratio=0.6, max_force_ratio=1.0,
                  settle_time=0.02, velocity_filter=0.01, unwind_time=0.1,
                  slip_residual=1e-3)


@pytest.fixture(params=['compiled', 'numpy'])
def new_loop(request):
    """Make object loops whose engaged step is compiled, or numpy's (the reference)."""
    if request.param == 'compiled' and loader.fast_cycle is None:
        pytest.skip(f'compiled module not built: {loader.IMPORT_ERROR}')

    def make():
        loop = ObjectLoop()
        loop.compiled = request.param == 'compiled'
        return loop
    return make


def carried(dx):
    """Give the configuration whose contact points carry the object by the rigid motion dx."""
    model = HAND.model
    data = model.createData()
    frames = [model.getFrameId(c.link) for c in SETUP.contacts]
    pin.framesForwardKinematics(model, data, SETUP.q)
    targets = [ORIGIN + dx[:3] + pin.exp3(dx[3:]) @ (data.oMf[f].act(c.position) - ORIGIN)
               for f, c in zip(frames, SETUP.contacts)]
    q = SETUP.q.copy()
    for _ in range(4):  # Gauss-Newton on the points: a small motion converges in a few steps
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        rows, rhs = [], []
        for f, c, target in zip(frames, SETUP.contacts, targets):
            J = pin.getFrameJacobian(model, data, f, pin.LOCAL_WORLD_ALIGNED)
            p = data.oMf[f].act(c.position)
            rows.append(J[:3] - pin.skew(p - data.oMf[f].translation) @ J[3:])
            rhs.append(target - p)
        q = q + np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]
    return q


def settled(loop, q0, t=0.0):
    """Run the loop through its settling at q0; return the time after."""
    while not loop.engaged:
        loop.after(True, np.zeros_like(LIMITS), LIMITS)
        loop.update(HAND, SETUP.contacts, q0, t, ORIGIN, WEIGHT, GAINS, 0.05)
        t += DT
    return t


def step(loop, q, t, certified=True, command=None):
    """One cycle: the last outcome noted, then the update at q."""
    loop.after(certified, np.zeros_like(LIMITS) if command is None else command, LIMITS)
    return loop.update(HAND, SETUP.contacts, q, t, ORIGIN, WEIGHT, GAINS, 0.05)


def wound_up(loop, n):
    """Settle, then hold the object 0.5 mm along -x for n cycles; return (q, the time)."""
    t = settled(loop, SETUP.q)
    q = carried(np.array([-0.5e-3, 0.0, 0.0, 0.0, 0.0, 0.0]))
    for k in range(n):
        step(loop, q, t + k * DT)
    return q, t + n * DT


def test_wrench_is_stiffness_and_integral_against_the_displacement(new_loop):
    loop = new_loop()
    t = settled(loop, SETUP.q)
    dx = np.array([-1e-3, 0.0, 0.0, 0.0, 0.0, 0.0])  # 1 mm along -x (the scenario's gravity)
    q = carried(dx)
    n = 10
    for k in range(n):
        w = step(loop, q, t + k * DT)
    assert loop.error[:3] == pytest.approx(dx[:3], abs=2e-5)
    # The hand pushes back along +x: w = -(K e + D edot + Ki integral(e)), D's part gone
    # once the filter has settled on a constant error (9 steps of 4 ms against 10 ms).
    expected = -(GAINS.stiffness * dx[0] + GAINS.integral * dx[0] * DT * n)
    assert w[0] > 0
    assert w[0] == pytest.approx(expected, rel=0.05)
    assert np.linalg.norm(w[1:3]) < 0.02 * w[0]


def test_integral_is_bounded_by_its_ratio_of_the_weight(new_loop):
    loop = new_loop()
    t = settled(loop, SETUP.q)
    q = carried(np.array([-1.5e-3, 0.0, 0.0, 0.0, 0.0, 0.0]))
    for k in range(400):  # 1.6 s of a 1.5 mm sag: Ki e t would be 7 N
        step(loop, q, t + k * DT)
    bound = GAINS.max_integral_ratio * WEIGHT
    integral_force = GAINS.integral * loop.integral[:3]
    assert np.linalg.norm(integral_force) == pytest.approx(bound, rel=1e-6)
    total = GAINS.max_force_ratio * WEIGHT
    assert np.linalg.norm(loop.wrench[:3]) <= total + 1e-9
    # With no error left, the wrench is the integral's alone: at its bound, not beyond.
    w = step(loop, SETUP.q, t + 400 * DT)
    assert np.linalg.norm(w[:3]) <= bound * 1.001 + GAINS.damping * 0.1


@pytest.mark.parametrize('outcome', ['limit', 'uncertified'])
def test_integral_unwinds_at_a_limit_and_without_a_certified_command(outcome, new_loop):
    loop = new_loop()
    q, t = wound_up(loop, 50)
    wound = loop.integral.copy()
    assert np.linalg.norm(wound[:3]) > 0
    at_limit = np.zeros_like(LIMITS)
    at_limit[3] = LIMIT_FRACTION * LIMITS[3]
    for k in range(50):  # 0.2 s = 2 unwind times: decays to e^-2 (implicit: a bit slower)
        if outcome == 'limit':
            step(loop, q, t + k * DT, command=at_limit)
        else:
            step(loop, q, t + k * DT, certified=False, command=None)
    ratio = np.linalg.norm(loop.integral[:3]) / np.linalg.norm(wound[:3])
    assert ratio == pytest.approx((GAINS.unwind_time / (GAINS.unwind_time + DT)) ** 50,
                                  rel=1e-9)
    assert ratio < 0.15
    assert loop.why_frozen == ('at a torque limit' if outcome == 'limit'
                               else 'no certified command')


def test_integral_frozen_while_a_contact_slips(new_loop):
    loop = new_loop()
    q, t = wound_up(loop, 20)
    before = loop.integral.copy()
    slipped = q.copy()
    slipped[HAND.idx_q[0]] += 0.1  # one finger's joint alone: its tip leaves the rigid motion
    step(loop, slipped, t)
    assert loop.residual.max() > GAINS.slip_residual
    assert loop.why_frozen == 'a contact slips'
    np.testing.assert_array_equal(loop.integral, before)


def test_reference_retaken_when_the_contact_set_changes(new_loop):
    loop = new_loop()
    t = settled(loop, SETUP.q)
    q = carried(np.array([-1e-3, 0.0, 0.0, 0.0, 0.0, 0.0]))
    step(loop, q, t)
    assert np.linalg.norm(loop.wrench) > 0
    changes = loop.changes
    w = loop.update(HAND, SETUP.contacts[:3], q, t + DT, ORIGIN, WEIGHT, GAINS, 0.05)
    assert loop.changes == changes + 1 and not loop.engaged
    np.testing.assert_array_equal(w, np.zeros(6))


def test_the_compiled_step_is_the_numpy_one():
    """Both steps over every branch: free, clamped, unwound at a limit and uncertified, slip."""
    if loader.fast_cycle is None:
        pytest.skip(f'compiled module not built: {loader.IMPORT_ERROR}')
    fast, slow = ObjectLoop(), ObjectLoop()
    slow.compiled = False
    at_limit = np.zeros_like(LIMITS)
    at_limit[3] = LIMIT_FRACTION * LIMITS[3]
    slipped = carried(np.array([-1e-3, 0.0, 0.0, 0.0, 0.0, 0.0]))
    slipped[HAND.idx_q[0]] += 0.1
    rng = np.random.default_rng(3)
    t = settled(slow, SETUP.q)
    assert settled(fast, SETUP.q) == t
    assert fast.tracker.compiled is not None  # else both ran numpy's
    frozen = set()
    for k in range(300):
        if k % 50 == 40:
            q, certified, command = slipped, True, None
        else:  # a sag and a turn that wind the integral up to its bound, and back
            dx = np.array([-1.5e-3, 0.4e-3, 0.0, 0.0, 0.01, 0.02]) * np.sin(k / 40.0)
            q = carried(dx + 1e-5 * rng.standard_normal(6))
            certified, command = k % 37 != 5, at_limit if k % 23 == 7 else None
        # The object origin moved off the reference's (an object pose input): the lever
        # is the new origin's, the estimate about the reference's.
        origin = ORIGIN + np.array([0.0, 0.0, 2e-3]) * (k > 150)
        for loop in (fast, slow):
            loop.after(certified, np.zeros_like(LIMITS) if command is None else command,
                       LIMITS)
            loop.update(HAND, SETUP.contacts, q, t, origin, WEIGHT, GAINS, 0.05)
        t += DT * (1.0 + 0.3 * rng.random())  # uneven periods, as joint states arrive
        for name in ('wrench', 'integral', 'error', 'rate', 'residual', 'slip', '_slow'):
            np.testing.assert_allclose(getattr(fast, name), getattr(slow, name),
                                       rtol=1e-9, atol=1e-12, err_msg=f'{name} at {k}')
        assert fast.why_frozen == slow.why_frozen
        frozen.add(slow.why_frozen)
    assert frozen == {'', 'no certified command', 'at a torque limit', 'a contact slips'}
    bound = GAINS.max_integral_ratio * WEIGHT  # the clamp was reached too
    assert np.linalg.norm(GAINS.integral * slow.integral[:3]) < bound * (1 + 1e-9)


def test_the_compiled_rotation_vector_is_pinocchios_log3():
    """Random rotations, small ones and ones near pi, against pinocchio.log3."""
    if loader.fast_cycle is None:
        pytest.skip(f'compiled module not built: {loader.IMPORT_ERROR}')
    rng = np.random.default_rng(5)
    axes = rng.standard_normal((200, 3))
    axes /= np.linalg.norm(axes, axis=1)[:, None]
    angles = np.concatenate((rng.uniform(0, np.pi, 50), 10.0 ** rng.uniform(-12, -2, 50),
                             np.pi - 10.0 ** rng.uniform(-9, -1, 50), np.zeros(1),
                             np.full(49, np.pi / 2)))
    for axis, angle in zip(axes, angles):
        R = pin.exp3(angle * axis)
        got, want = loader.fast_cycle.rotation_vector(R), pin.log3(R)
        if angle > np.pi - 1e-6:  # the axis's sign is not defined at pi: either one
            assert min(np.abs(got - want).max(), np.abs(got + want).max()) < 1e-6
        else:
            np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-14)


def test_squeeze_rises_with_usage_and_relaxes_within_its_bounds():
    loop = ObjectLoop()
    gains = LoopGains(squeeze=True, raise_at=0.5, relax_at=0.2, rate=2.0, relax_rate=2.0,
                      max_normal_force=1.0)
    base, t = 0.2, 0.0
    squeeze = loop.squeeze
    for k in range(150):  # 0.6 s at usage 0.9: +1.2 N, capped at 1.0 N
        squeeze.update(base, np.array([0.1, 0.9, 0.1, 0.1]), t, gains, (True, False), 0.05)
        t += DT
    assert squeeze.normal_force == pytest.approx(1.0, abs=0.02)
    level = squeeze.normal_force
    squeeze.update(base, np.array([0.1, 0.9]), t, gains, (True, True), 0.05)  # at a limit
    assert squeeze.normal_force <= level
    # A source's measured usage (a tactile plug-in's) is used while fresh.
    squeeze.measured(np.array([0.0, 0.05, 0.0, 0.0]), t, 'tactile')
    for k in range(10):
        squeeze.update(base, np.array([0.9, 0.9, 0.9, 0.9]), t + k * DT, gains, (True, False),
                       0.05)
    assert squeeze.source == 'tactile'
    assert squeeze.normal_force < level
    for k in range(200):
        squeeze.update(base, np.zeros(4), t + 1.0 + k * DT, gains, (True, False), 0.05)
    assert squeeze.source == 'slip'
    assert squeeze.normal_force == pytest.approx(base)


def test_the_loop_state_is_on_the_diagnostic_report():
    from cycle_inputs import fresh, joint_state
    from grasp_torque_opt.control.diagnostics import report
    from grasp_torque_opt.control.inputs.joint_states import JointStateReading

    ctrl = fresh(SETUP, object_loop=True, loop_settle_time=0.02, joint_state_timeout=1.0)
    assert dict(report(ctrl, 0.0).values)['object_loop'].startswith('no reference')
    ctrl.solving.weight = WEIGHT  # as the node sets it from the scenario
    t = 0.0

    def cycle(q):
        nonlocal t
        t += DT
        ctrl.take('joint_states', JointStateReading(*joint_state(SETUP, q)), t)
        ctrl.cycle(t)
        return dict(report(ctrl, t).values)

    v = cycle(SETUP.q)
    assert v['object_loop'] == 'settling' and v['object_loop.settlings'] == '1', v
    while v['object_loop'] != 'engaged' and t < 0.1:
        v = cycle(SETUP.q)
    assert v['object_loop'] == 'engaged' and float(v['object_loop.deviation_mm']) < 1e-3
    # The fingertips carry the object 1 mm along -x and 1 deg about z: the report says so.
    for _ in range(3):
        v = cycle(carried(np.array([-1e-3, 0.0, 0.0, 0.0, 0.0, np.radians(1.0)])))
    assert float(v['object_loop.deviation_mm']) == pytest.approx(1.0, abs=0.02), v
    assert float(v['object_loop.rotation_deg']) == pytest.approx(1.0, abs=0.02), v
    assert v['object_loop.integral'] == 'moving' and v['object_loop.max_slip_mm'] != 'none'
    force = [float(x) for x in v['object_loop.wrench'].strip('[]').split(',')[:3]]
    assert force[0] > 0  # pushing back along +x
    off = fresh(SETUP)
    assert dict(report(off, 0.0).values)['object_loop'] == 'off (object_loop.enabled false)'
