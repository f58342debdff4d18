# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The planner's IK on the real Allegro and G1: its shortcuts against the full evaluation.

The residuals the IK solves (far shapes bounded, not measured; a contact mesh far from
the object taken at its convex hull) are compared with those written here from every
shape's coal distance (:meth:`SurfaceIK.evaluate` without a band, each shape measured);
the Jacobian with central differences of the residuals; the IK's stopping point with
every collision shape measured by coal directly, outside the IK's classes.
"""

import coal
from conftest import ALLEGRO, CONFIG
from grasp_torque_opt.core.geometry_contacts import collision_model
from grasp_torque_opt.core.grasp_setup import bind_for_candidates
from grasp_torque_opt.core.hand import resolve_urdf
from grasp_torque_opt.core.object_geometry import ObjectShape
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.methods import plan_ik
from grasp_torque_opt.methods.plan import plan_grasps, PlanSettings
from grasp_torque_opt.methods.plan_ik import SurfaceIK
import numpy as np
import pinocchio as pin
import pytest

G1 = CONFIG / 'g1_right.yaml'
CLEARANCE = 2e-3
TARGET = 1.25 * CLEARANCE  # the IK's band (SurfaceIK.solve)


def bound(path, shape=None, edge=0.0):
    """Return (ik, base q, base object origin, the object shape) of a bundled scenario."""
    scenario = load_scenario(path)
    setup, _ = bind_for_candidates(scenario)
    shape = shape or ObjectShape.from_spec(scenario.object)
    links = [c.link for c in scenario.contacts]
    urdf = resolve_urdf(scenario.urdf, scenario.base_dir)
    return (SurfaceIK(setup.hand, urdf, shape, links, edge), setup.q,
            np.asarray(scenario.object_origin, float), shape, urdf)


@pytest.fixture(scope='module')
def iks():
    return {'allegro box': bound(ALLEGRO, ObjectShape('box', np.array([0.05, 0.05, 0.07])),
                                 3e-3),
            'allegro sphere': bound(ALLEGRO), 'g1 sphere': bound(G1)}


def draws(ik, q_base, origin, count, seed, spread=0.15):
    """Draw (x, rotation) about the base grasp: x = (theta, object position)."""
    rng = np.random.default_rng(seed)
    theta_base = q_base[ik.hand.idx_q]
    for _ in range(count):
        theta = theta_base + rng.normal(0.0, spread, ik.hand.m)
        p = origin + rng.uniform(-0.01, 0.01, 3)
        R = pin.rpy.rpyToMatrix(*rng.uniform(-0.3, 0.3, 3))
        yield np.concatenate([theta, p]), R


def full_rows(ik, x, q_base, R):
    """Return the IK's distance rows, every shape measured: contacts, others' hinges."""
    m = ik.hand.m
    d = [row[0] for row in ik.evaluate(ik.full_q(x[:m], q_base), pin.SE3(R, x[m:]))]
    contacts = [min(d[i] for i in shapes) for shapes in ik.contact_shapes]
    others = [max(TARGET - d[i], 0.0) for i in ik.other_shapes]
    return np.array(contacts), np.array(others), d


@pytest.mark.parametrize('case', ['allegro box', 'allegro sphere', 'g1 sphere'])
def test_bounded_residuals_are_the_full_evaluations(iks, case):
    """Far shapes' rows are 0 as measured; a contact is its mesh's distance near it."""
    ik, q_base, origin, _, _ = iks[case]
    c, n = len(ik.contact_links), len(ik.other_shapes)
    skipped = 0
    for x, R in draws(ik, q_base, origin, 12, seed=1):
        f, _ = ik._residuals(x, x[:ik.hand.m], x[ik.hand.m:], R, q_base, TARGET)
        contacts, others, d = full_rows(ik, x, q_base, R)
        np.testing.assert_allclose(f[c:c + n], others, rtol=0, atol=1e-9)
        for got, want in zip(f[:c], contacts):
            # a contact mesh's convex hull is no farther than the mesh
            assert got <= want + 1e-9
            if got <= plan_ik.APPROACH:
                assert got == pytest.approx(want, abs=1e-9)
        # the first phase (meshes at their hulls): no contact farther, no hinge smaller
        ik._hulls_only = True
        try:
            hulls, _ = ik._residuals(x, x[:ik.hand.m], x[ik.hand.m:], R, q_base, TARGET)
        finally:
            ik._hulls_only = False
        assert np.all(hulls[:c] <= contacts + 1e-9)
        assert np.all(hulls[c:c + n] >= others - 1e-9)
        # every bound is a lower bound of its shape's distance
        m = ik.hand.m
        bounds = ik.evaluate(ik.full_q(x[:m], q_base), pin.SE3(R, x[m:]), band=np.inf)
        for (b, *rest), exact in zip(bounds, d):
            assert b <= exact + 1e-9
            skipped += rest[0] is None
    assert skipped > 0  # the broad phase did bound some shapes


@pytest.mark.parametrize('case', ['allegro box', 'allegro sphere', 'g1 sphere'])
def test_the_jacobian_is_the_residuals_derivative(iks, case):
    """Analytic Jacobian rows against central differences, where the rows are smooth."""
    ik, q_base, origin, _, _ = iks[case]
    m, h = ik.hand.m, 1e-6
    checked = 0
    for x, R in draws(ik, q_base, origin, 4, seed=2, spread=0.05):
        x0 = x.copy()

        def f(y):
            return ik._residuals(y, x0[:m], x0[m:], R, q_base, TARGET)

        f0, J = f(x)
        numeric = np.empty_like(J)
        for j in range(x.size):
            step = np.zeros_like(x)
            step[j] = h
            numeric[:, j] = (f(x + step)[0] - f(x - step)[0]) / (2 * h)
        # The edge rows take the object's nearest point as moving with the link (the
        # module's model, not the derivative): the distance rows and the pulls only.
        for k in range(f0.size - 2 * len(ik.contact_links)):
            # a hinge at its kink or a hull / mesh switch: not smooth
            if abs(f0[k]) < 1e-5 or abs(f0[k] - plan_ik.APPROACH) < 1e-4:
                continue
            np.testing.assert_allclose(J[k], numeric[k], rtol=2e-3, atol=2e-5,
                                       err_msg=f'{case} row {k}')
            checked += 1
    assert checked >= 4 * len(ik.contact_links)


def by_coal(ik, geom, target, q, pose_in_base) -> dict[str, float]:
    """Return every link's least distance to the object, coal on ``geom`` directly."""
    model = ik.model
    data, gdata = model.createData(), pin.GeometryData(geom)
    pin.framesForwardKinematics(model, data, q)
    pin.updateGeometryPlacements(model, data, geom, gdata)
    base = (data.oMf[model.getFrameId(ik.hand.base_link)] if ik.hand.base_link
            else pin.SE3.Identity())
    pose = base * pose_in_base
    least: dict[str, float] = {}
    for i, g in enumerate(geom.geometryObjects):
        oMg = gdata.oMg[i]
        d = coal.distance(g.geometry, coal.Transform3s(oMg.rotation, oMg.translation),
                          target, coal.Transform3s(pose.rotation, pose.translation),
                          coal.DistanceRequest(), coal.DistanceResult())
        link = model.frames[g.parentFrame].name
        least[link] = min(d, least.get(link, np.inf))
    return least


@pytest.mark.parametrize('case', ['allegro sphere', 'g1 sphere'])
def test_the_ik_stops_where_every_shape_measured_by_coal_meets_its_test(iks, case):
    """Each stop point: contacts within half the tolerance, every other shape clear."""
    ik, q_base, origin, shape, urdf = iks[case]
    tolerance, m = 5e-4, ik.hand.m
    model = ik.model
    lower, upper = model.lowerPositionLimit[ik.hand.idx_q], model.upperPositionLimit[
        ik.hand.idx_q]
    geom = collision_model(ik.hand, urdf)  # its own shapes, not the IK's
    target = coal.Sphere(shape.size[0])
    stopped = 0
    for x, R in draws(ik, q_base, origin, 6, seed=3):
        region = (x[m:] - 0.02, x[m:] + 0.02)
        sol = ik.solve(np.clip(x[:m], lower, upper), x[m:], R, q_base, (lower, upper),
                       region, CLEARANCE, tolerance=tolerance)
        if not sol.stopped:
            continue
        stopped += 1
        least = by_coal(ik, geom, target, ik.full_q(sol.theta, q_base),
                        pin.SE3(R, sol.position))
        for k in ik.contact_links:
            assert abs(least[k]) <= plan_ik.STOP_SHARE * tolerance + 1e-7, (k, least[k])
        for k, d in least.items():
            if k not in ik.contact_links:
                assert d >= CLEARANCE, (k, d)
    assert stopped >= 2


def test_planned_g1_candidates_touch_with_their_links_and_nothing_else(iks):
    """The G1's lines (its meshes, the whole robot's shapes), measured by coal directly."""
    ik, q_base, _, shape, urdf = iks['g1 sphere']
    settings = PlanSettings(count=3, seed=2)
    plan = plan_grasps(G1, settings)
    assert len(plan.candidates) == 3
    geom = collision_model(ik.hand, urdf)
    for line in plan.candidates:
        theta = np.array([line['grasp']['joint_positions'][j] for j in ik.hand.joints])
        obj = line['object']
        pose = pin.SE3(pin.rpy.rpyToMatrix(*obj['rpy']), np.array(obj['position']))
        least = by_coal(ik, geom, coal.Sphere(shape.size[0]), ik.full_q(theta, q_base), pose)
        assert [c['link'] for c in line['grasp']['contacts']] == ik.contact_links
        for k, d in least.items():
            if k in ik.contact_links:
                assert abs(d) <= settings.tolerance, (k, d)
            else:
                assert d >= settings.clearance, (k, d)


def rosenbrock(x):
    """Rosenbrock's residuals and their Jacobian."""
    return (np.array([10.0 * (x[1] - x[0] ** 2), 1.0 - x[0]]),
            np.array([[-20.0 * x[0], 10.0], [-1.0, 0.0]]))


@pytest.mark.parametrize('box', [((-2.0, -2.0), (2.0, 2.0)), ((-2.0, -2.0), (0.5, 2.0)),
                                 ((-2.0, 1.5), (2.0, 3.0))])
def test_the_ik_solver_finds_what_scipys_least_squares_finds(box):
    """Rosenbrock within bounds (free, and its optimum cut off by each bound) vs SciPy."""
    from scipy.optimize import least_squares
    lower, upper = np.array(box[0]), np.array(box[1])
    x0 = np.clip(np.array([-1.2, 1.0]), lower, upper)
    x, cost, converged = plan_ik.levenberg_marquardt(rosenbrock, x0, lower, upper, 500)
    ref = least_squares(lambda v: rosenbrock(v)[0], x0, jac=lambda v: rosenbrock(v)[1],
                        bounds=(lower, upper), xtol=1e-12, ftol=1e-12, gtol=1e-12)
    assert converged
    assert np.all((lower <= x) & (x <= upper))
    np.testing.assert_allclose(x, ref.x, atol=1e-6)
    assert cost == pytest.approx(ref.cost, abs=1e-10)


def test_the_ik_solver_keeps_to_its_evaluations():
    """Out of evaluations it says so, and never asks for one more."""
    calls = []

    def counted(x):
        calls.append(x.copy())
        return rosenbrock(x)

    lower, upper = np.full(2, -2.0), np.full(2, 2.0)
    x, _, converged = plan_ik.levenberg_marquardt(counted, np.array([-1.2, 1.0]), lower,
                                                  upper, 5)
    assert len(calls) == 5 and not converged
    assert any(np.array_equal(x, c) for c in calls)


@pytest.mark.parametrize('where', ['start', 'steps'])
def test_the_ik_solver_stops_at_residuals_that_are_not_finite(where):
    """Residuals that are not finite (at the start, or at a step tried) end it, unconverged."""
    start = np.array([-1.2, 1.0])

    def broken(x):
        if where == 'start' or not np.array_equal(x, start):
            return np.full(2, np.nan), np.full((2, 2), np.nan)
        return rosenbrock(x)

    lower, upper = np.full(2, -2.0), np.full(2, 2.0)
    x, cost, converged = plan_ik.levenberg_marquardt(broken, start, lower, upper, 30)
    assert not converged and np.array_equal(x, start)
    assert (cost == rosenbrock(start)[0] @ rosenbrock(start)[0] / 2) == (where == 'steps')
