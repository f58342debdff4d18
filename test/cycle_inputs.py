# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Inputs for the control cycle shared by the controller, node and campaign tests.

Joint states and contact poses of a scenario's grasp, a controller on fresh
inputs, and :class:`Injected`, a solver that fails on purpose in every way a
real one can (for the fault paths; the healthy path is the real ProxSuite).
"""

import dataclasses
import time

from grasp_torque_opt.backends.proxsuite import TauQPSolver
from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.control.parameters.generated import CycleConfig
from grasp_torque_opt.core.exceptions import SolverError
from grasp_torque_opt.core.solution import RawResult
import numpy as np
import pinocchio as pin


def joint_state(setup, q=None, names=None):
    q = setup.q if q is None else q
    hand = setup.hand
    names = names or hand.one_dof_joints(hand.model)
    return names, [float(q[hand.model.joints[hand.model.getJointId(n)].idx_q]) for n in names]


def fresh(setup, **config):
    """
    Make a controller of its own, with a generous cycle budget unless a test is about it.

    Other processes may load this machine.
    """
    config.setdefault('cycle_budget', 10.0)
    return TorqueController(dataclasses.replace(setup, hand=dataclasses.replace(setup.hand)),
                            CycleConfig(**config))


def base_poses(setup, q=None):
    """Give the default contact frames at q, as (positions, xyzw quaternions) in the base frame."""
    maps = dataclasses.replace(setup, q=setup.q if q is None else q).maps()
    pos = np.array([f.position for f in maps.contacts])
    quat = np.array([pin.Quaternion(f.rotation).coeffs() for f in maps.contacts])
    return pos, quat


def flipped(quat: np.ndarray) -> np.ndarray:
    """Turn each contact frame half a turn about its x axis: its normal z points outward."""
    half = pin.Quaternion(pin.exp3(np.array([np.pi, 0.0, 0.0])))
    return np.array([(pin.Quaternion(q[3], *q[:3]) * half).coeffs() for q in quat])


def tilted(quat: np.ndarray, angle: float) -> np.ndarray:
    """Turn each contact frame about its x axis by ``angle``: its normal still points inward."""
    turn = pin.Quaternion(pin.exp3(np.array([angle, 0.0, 0.0])))
    return np.array([(pin.Quaternion(q[3], *q[:3]) * turn).coeffs() for q in quat])


class Injected:
    """
    A tau-QP solver (``solve(qp) -> RawResult``, ``settings``) that fails on purpose.

    ``mode`` says how; ``healthy`` makes it the real one again.
    """

    def __init__(self, mode: str):
        self.inner = TauQPSolver()
        self.settings = self.inner.settings
        self.mode = mode
        self.healthy = False

    def solve(self, qp):
        if self.healthy:
            return self.inner.solve(qp)
        if self.mode == 'raise-solver':
            raise SolverError('injected: ProxSuite failed')
        if self.mode == 'raise-other':
            raise ZeroDivisionError('injected')
        if self.mode == 'nan-data':  # the real solver must refuse it at once
            return self.inner.solve(dataclasses.replace(qp, H=qp.H * np.nan))
        if self.mode == 'inverted-bounds':
            return self.inner.solve(dataclasses.replace(qp, l_box=qp.u_box + 1.0))
        good = self.inner.solve(qp)
        if self.mode == 'max-iter':
            return RawResult('error', good.x, 1000, 0.01, 'PROXQP_MAX_ITER_REACHED')
        if self.mode == 'wrong-x':  # finite, claimed solved, but not a solution
            return RawResult('solved', good.x + 0.05, good.iterations, good.solve_time_s,
                             'PROXQP_SOLVED')
        if self.mode == 'nan-x':
            return RawResult('solved', good.x * np.nan, 1, 0.0, 'PROXQP_SOLVED')
        if self.mode == 'wrong-size-x':
            return RawResult('solved', good.x[:-1], 1, 0.0, 'PROXQP_SOLVED')
        raise AssertionError(self.mode)


class Slow:
    """
    A solver that answers correctly, late (it takes no deadline).

    With it a cycle or a service call outlasts its budget or its inputs.
    """

    def __init__(self, delay: float):
        self.inner, self.delay = TauQPSolver(), delay
        self.settings = self.inner.settings

    def solve(self, qp):
        time.sleep(self.delay)
        return self.inner.solve(qp)


FAULT_MODES = ['raise-solver', 'raise-other', 'nan-data', 'inverted-bounds', 'max-iter',
               'wrong-x', 'nan-x', 'wrong-size-x']


def phantom(setup, links=('link_7.0',)):
    """
    Give the grasp's contact poses and one more at each of ``links``' frames.

    Each extra pose's normal points to the object origin: a point on its link, 0 mm from
    its frame, off the object's surface.
    """
    points, quat = base_poses(setup)
    model = setup.hand.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, setup.q)
    for link in links:
        p = data.oMf[model.getFrameId(link)].translation
        z = setup.object_origin - p
        z /= np.linalg.norm(z)
        x = np.cross([0.0, 1.0, 0.0], z)
        x /= np.linalg.norm(x)
        R = np.column_stack((x, np.cross(z, x), z))
        points, quat = np.vstack((points, p)), np.vstack((quat, pin.Quaternion(R).coeffs()))
    return points, quat
