# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""What the node says on /diagnostics: a pure function of the controller's state."""

from __future__ import annotations

from dataclasses import dataclass

from grasp_torque_opt.control.controller import TorqueController
from grasp_torque_opt.core.friction import friction_usage
import numpy as np

# diagnostic_msgs/DiagnosticStatus levels, without importing ROS.
OK, WARN, ERROR, STALE = 0, 1, 2, 3


@dataclass(frozen=True)
class Report:
    """One diagnostic status: level, message and key-value pairs (strings)."""

    level: int
    message: str
    values: list[tuple[str, str]]


def _ago(now: float, t: float | None) -> str:
    return 'never' if t is None else f'{now - t:.4f}'


def report(controller: TorqueController, now: float) -> Report:
    """
    Report the controller's state as a diagnostic status.

    Level: STALE before the first joint state, OK while certified commands flow,
    WARN during a fault while the last certified command is held (within
    ``hold_time``), ERROR once the fault policy applies.
    """
    c = controller
    cfg = c.config
    level, message = _level(c, now)
    values: list[tuple[str, str]] = []
    values.append(('fault', c.fault or 'none'))
    # The order of the command's values: a controller with a fixed joint list must match it.
    values.append(('command_joints', ','.join(c.setup.hand.joints)))
    values.append(('fault_policy', cfg.fault_policy))
    values += interface_values(c)
    values += solution_values(c)
    last = c.last
    if last is not None and last.gravity_torque is not None:
        values.append(('gravity_torque_norm',
                       f'{float((last.gravity_torque ** 2).sum() ** 0.5):.6f}'))
    n = c.counters
    values += [('cycles', str(n.cycles)), ('commands', str(n.commands)),
               ('zero_commands', str(n.zero_commands)), ('faults', str(n.faults)),
               ('recoveries', str(n.recoveries)), ('solver_failures', str(n.solver_failures)),
               ('overruns', str(n.overruns)), ('slew_limited', str(n.slew_limited)),
               ('slew_refused', str(n.slew_refused)),
               ('max_cycle_time_s', f'{n.max_cycle_time:.6f}'),
               ('cycle_budget_s', f'{cfg.cycle_budget:.6f}')]
    values += solver_values(c)
    values += motion_values(c, now)
    values += object_loop_values(c)
    values += contact_values(c, now)
    if level == OK and c.solving.imu_state:
        level, message = WARN, f'certified torques published; {c.solving.imu_state}'
    tactile, said = tactile_values(c, now)
    values += tactile
    if level == OK and said:
        level, message = WARN, f'certified torques published; {said}'
    values += [(f'rejected.{k}', str(v)) for k, v in n.rejected.items()]
    values.append(('last_rejection', c.last_rejection or 'none'))
    values += [('age.joint_states_s', _ago(now, c.inputs.q_time)),
               ('age.contacts_s', _ago(now, c.inputs.contacts_time)),
               ('age.external_wrench_s', _ago(now, c.inputs.wrench_time))]
    return Report(level, message, values)


def _level(c: TorqueController, now: float) -> tuple[int, str]:
    """Give the level and message of :func:`report` before the IMU's say."""
    cfg = c.config
    if c.inputs.q is None:
        return STALE, 'waiting for joint_states'
    if not c.fault:
        return OK, 'certified torques published'
    held = (c.last_command_time is not None
            and now - c.last_command_time <= cfg.hold_time)
    if held:
        return WARN, f'holding last certified command: {c.fault}'
    if cfg.fault_policy == 'zero':
        return ERROR, f'zero torques published: {c.fault}'
    return ERROR, f'hold policy, last certified command kept: {c.fault}'


def solution_values(c: TorqueController) -> list[tuple[str, str]]:
    """Give the last solution's values: status, times, certificate, friction per contact."""
    last = c.last
    sol = last.solution if last is not None else None
    if sol is None:
        return []
    values = [('status', sol.status), ('solver_message', sol.message),
              ('solve_time_s', f'{sol.solve_time_s:.6f}'),
              ('cycle_time_s', f'{last.cycle_time or sum(sol.timings.values()):.6f}'),
              ('iterations', str(sol.iterations))]
    if sol.certificate is not None:
        cert = sol.certificate.as_dict()
        values += [(f'certificate.{k}', f'{cert[k]:.3e}')
                   for k in ('equilibrium', 'torque', 'cone', 'normal_force',
                             'torque_limit')]
        values.append(('certificate.ok', str(sol.certificate.ok).lower()))
    if sol.optimal and last.maps is not None:
        values.append(('torque_norm', f'{sol.torque_norm:.6f}'))
        values += [('objective', sol.objective),
                   ('friction_margin', f'{sol.friction_margin:g}'),
                   ('max_torque_ratio', f'{sol.max_torque_ratio:.4f}'),
                   ('friction_usage_max', f'{float(sol.friction_usage.max()):.4f}')]
        usage = friction_usage(sol.wrenches, c.setup.friction.mu1, c.setup.friction.mu2)
        for i, (frame, (ut, ur)) in enumerate(zip(last.maps.contacts, usage)):
            key = f'contact{i}.{frame.link}'
            values += [(f'{key}.normal_force_N', f'{sol.wrenches[i, 2]:.4f}'),
                       (f'{key}.friction_usage', f'{sol.friction_usage[i]:.4f}'),
                       (f'{key}.tangential_usage', f'{ut:.4f}'),
                       (f'{key}.torsional_usage', f'{ur:.4f}')]
    return values


def solver_values(c: TorqueController) -> list[tuple[str, str]]:
    """Give the backend's values and the compiled cycle's: in use or why not, its counts."""
    n = c.counters
    solver = c.solver
    values = [('solver.backend', getattr(solver, 'name', type(solver).__name__)),
              ('solver.warm_solves', str(getattr(solver, 'warm_solves', 0))),
              ('solver.warm_start_fallbacks', str(getattr(solver, 'fallbacks', 0))),
              ('solver.fallback_solves', str(n.fallback_solves))]
    fast = c.compiled_cycle
    values += [('solver.compiled', 'true' if fast is not None and not fast.gave_up else
                f'false: {c.compiled_reason}' if c.compiled_reason else 'no cycle yet'),
               ('solver.compiled_module', fast.module.__name__.rsplit('.', 1)[-1]
                if fast is not None else 'none'),
               ('solver.compiled_solves', str(fast.solves if fast is not None else 0)),
               ('solver.compiled_handed_back', str(fast.handed_back if fast is not None else 0))]
    return values


def motion_values(c: TorqueController, now: float) -> list[tuple[str, str]]:
    """Give the IMU's and the effort estimation's values: in use or why not, the load."""
    solving, inputs = c.solving, c.inputs
    values = [('imu', 'none received' if inputs.motion is None else
               solving.imu_state or 'in use'),
              ('age.imu_s', _ago(now, inputs.motion_time)),
              ('imu.refused', c.store.imu.refused or 'none')]
    if inputs.motion is not None:
        values += [('imu.apparent_gravity', _vector(inputs.motion.gravity)),
                   ('imu.timeout_s', f'{inputs.motion.timeout:.4f}')]
    est = solving.effort_load
    if not c.config.effort_estimation:
        values.append(('effort_estimation', 'off (effort_estimation.enabled false)'))
    else:
        values.append(('effort_estimation', est.off or 'on'))
        if est.agreement is not None and not est.off:  # the gate (Load from efforts)
            values.append(('load.gate', est.agreement.state or 'open'))
        if est.estimate is not None:
            values.append(('load.estimated', _vector(est.estimate)))
        if est.estimate is not None or est.agreement is not None:
            values.append(('load.correction', _vector(est.correction)))
    if solving.load is not None:
        values.append(('load.planned', _vector(solving.load)))
    return values


def interface_values(c: TorqueController) -> list[tuple[str, str]]:
    """Give the command interface, and for a position-like one the held reference q_hold."""
    interface = c.policy.interface
    values = [('command_interface', interface.name)]
    held = getattr(interface, 'held', None)
    if held is not None:
        values.append(('command_interface.q_hold', 'not taken (no certified command yet)'
                       if held.q_hold is None else _vector(held.q_hold)))
    return values


def object_loop_values(c: TorqueController) -> list[tuple[str, str]]:
    """
    Give the object loop's state: engaged or settling, the object's deviation, its wrench.

    The deviation is the loop's own error (the object's displacement from the fingertips,
    since the reference was taken), not the fingertips' drift from the scenario's pose.
    """
    if not c.config.object_loop:
        return [('object_loop', 'off (object_loop.enabled false)')]
    loop = c.solving.object_loop
    state = ('engaged' if loop.engaged else 'settling' if loop.tracker is not None
             else 'no reference (no contacts or no weight)')
    e, w = loop.error, loop.wrench
    values = [('object_loop', state),
              ('object_loop.deviation_mm', f'{1e3 * np.linalg.norm(e[:3]):.3f}'),
              ('object_loop.rotation_deg', f'{np.degrees(np.linalg.norm(e[3:])):.3f}'),
              ('object_loop.wrench', _vector(w)),
              ('object_loop.integral', loop.why_frozen and f'frozen: {loop.why_frozen}'
               or 'moving'),
              ('object_loop.settlings', str(loop.changes)),
              ('object_loop.max_slip_mm', f'{1e3 * float(loop.slip.max()):.3f}'
               if loop.slip.size else 'none')]
    force = loop.squeeze.normal_force
    if force is not None:
        values.append(('squeeze.min_normal_force_N', f'{force:.4f}'))
    return values


def contact_values(c: TorqueController, now: float) -> list[tuple[str, str]]:
    """Give where the contacts come from, their set and its changes, the object pose."""
    solving, inputs = c.solving, c.inputs
    tracker = solving.tracker
    source = ('contacts topic' if inputs.contacts is not None else
              'geometry' if tracker is not None else 'scenario')
    values = [('contacts.source', source)]
    if inputs.contacts is not None:  # the set in force: named, or the scenario's by index
        links = inputs.contacts.links or tuple(s.link for s in c.setup.contacts)
        values += [('contacts.links', ','.join(links)),
                   ('contacts.changes', str(solving.topic_changes))]
    elif tracker is not None:
        values += [('contacts.links', ','.join(tracker.links or ()) or 'none'),
                   ('contacts.changes', str(tracker.changes))]
    values += [('object_pose', "none received (the scenario's)" if inputs.object_pose is None
                else 'in use'),
               ('age.object_pose_s', _ago(now, inputs.object_pose_time))]
    return values + fingertip_values(c)


def fingertip_values(c: TorqueController) -> list[tuple[str, str]]:
    """Give where the fingertips place the object, and how far the object_pose is from it."""
    est, q = c.store.hand_object, c.inputs.q
    if est is None or q is None:
        return []
    hand = c.setup.hand
    tips = est.estimate(hand.complete(q.copy()) if hand.coupling.mimics else q)
    values = [('object.fingertips.drift_mm', f'{1e3 * np.linalg.norm(tips.translation):.3f}'),
              ('object.fingertips.rotation_deg',
               f'{np.degrees(np.linalg.norm(tips.rotation)):.3f}'),
              ('object.fingertips.residual_mm', f'{1e3 * tips.residual:.3f}')]
    pose = c.solving.pose_in_use
    if c.inputs.object_pose is not None and pose is not None:
        values.append(('object_pose.deviation_mm',
                       f'{1e3 * np.linalg.norm(pose.translation - tips.pose.translation):.3f}'))
    return values


def tactile_values(c: TorqueController, now: float) -> tuple[list[tuple[str, str]], str]:
    """
    Give the tactile input's values, and what it warns of ('' for nothing).

    Per contact of the last certified command, against the readings aged at ``now``: the
    measured normal force and the measured friction usage
    (:mod:`grasp_torque_opt.control.tactile`); the contacts lost (measured below
    ``tactile.loss_ratio`` times planned) and those without a fresh reading.
    """
    cfg, inputs = c.config, c.inputs
    if cfg.tactile_source == 'none':
        return [('tactile', 'off (tactile.source none)')], ''
    values = [('age.tactile_s', _ago(now, inputs.tactile_time))]
    rep = c.solving.tactile
    if inputs.tactile is None or rep is None:
        state = 'none received' if inputs.tactile is None else 'no certified command yet'
        return [('tactile', state)] + values, f'tactile: {state}'
    rep = rep.at(inputs.tactile, now, cfg, c.setup.friction.mu1)  # the readings' ages now
    for i, link in enumerate(rep.links):
        key = f'contact{i}.{link}'
        values += [(f'{key}.measured_normal_force_N', f'{rep.measured[i]:.4f}'),
                   (f'{key}.measured_friction_usage', f'{rep.usage[i]:.4f}')]
    lost = [f'{rep.links[i]} ({rep.measured[i]:.3f} N of {rep.planned[i]:.3f} N planned)'
            for i in rep.lost]
    stale = [rep.links[i] for i in rep.stale]
    stale += [f'{rep.links[i]} (pulling)' for i in rep.pulling]
    values += [('tactile.lost', ', '.join(lost) or 'none'),
               ('tactile.stale', ', '.join(stale) or 'none')]
    said = '; '.join(([f'contact lost: {", ".join(lost)}'] if lost else [])
                     + ([f'stale: {", ".join(stale)}'] if stale else []))
    values.insert(0, ('tactile', said or 'in use'))
    return values, f'tactile {said}' if said else ''


def _vector(v) -> str:
    return ','.join(f'{float(x):.5g}' for x in v)
