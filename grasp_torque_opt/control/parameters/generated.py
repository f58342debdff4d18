# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

# Generated from grasp_torque_opt/control/grasp_torque_node_parameters.yaml by
# python -m grasp_torque_opt.control.parameters.generate: do not edit, regenerate.

"""
The node's parameters as typed, frozen dataclasses, generated from the schema.

As generate_parameter_library writes a node's parameters module, every field is written
out with its type (and, for :class:`CycleConfig`, its default) from
``grasp_torque_node_parameters.yaml``; test/control/test_parameters.py fails when this
file is not the one the schema gives.

- :class:`CycleConfig`: the cycle's settings, one field per entry with a ``cycle`` key.
- :class:`Params`: the frozen snapshot of every value (``p.solver.backend``), one class
  per namespace, a value None while the parameter has none
  (:mod:`~grasp_torque_opt.control.parameters.snapshot` makes and reads it).
- :data:`CYCLE_FIELDS`: each :class:`CycleConfig` field's parameter.
"""

from dataclasses import dataclass


@dataclass(frozen=True)
class CycleConfig:
    """
    Timing and safety settings of the cycle: the entries with a ``cycle`` key.

    Attributes:
        gravity_compensation: Add the fingers' own gravity torques g(q); the torque limits then
            bound tau + g(q).
        hold_object: false: the hand holds no object: no grasp is solved, the command is g(q) alone
            (finger gravity compensation; zero torques without gravity_compensation), the contacts'
            wrenches fading out by the rate rule; true again: the grasp fades in (docs/node.md, "No
            object: finger gravity compensation").
        gravity: Gravity in the base frame for g(q) and, where the scenario's load is its object's
            weight, for the load (the Allegro scenario: [9.81, 0, 0], palm down); once a message
            arrives on the gravity topic, the topic's gravity is used instead. [m/s^2]
        joint_state_timeout: Joint states older than this stop commands. [s]
        contacts_timeout: Once contacts arrived, older than this stop commands; 0, never stale. [s]
        wrench_timeout: Once a load arrived on external_wrench, older than this stops commands; 0,
            never stale. [s]
        gravity_timeout: Once gravity arrived on the gravity topic, older than this stops commands
            (a fault, as any stale input); 0, never stale. [s]
        hold_time: How long a fault may hold the last certified command before the fault policy
            applies. [s]
        fault_policy: After hold_time in a fault: hold (publish nothing, the effort controller
            keeps the last certified command) or zero (publish zero torques); docs/node.md, Faults.
        max_message_bytes: A message on joint_states, contacts, external_wrench or gravity whose
            serialized form is longer than this is rejected before it is deserialized. [bytes]
        max_joint_state_entries: A joint state with more names or positions than this is rejected
            unread.
        max_wrench_force: A load whose force norm exceeds this is rejected. [N]
        max_wrench_torque: A load whose moment norm exceeds this is rejected. [N m]
        max_contact_distance: A contact point farther than this from the base origin stops commands
            (a fault). [m]
        max_contact_link_distance: For a link without collision geometry in the URDF: a contact
            point on the contacts topic farther than this from its own link's frame is rejected
            (another finger's contact, a wrong frame); in the cycle, at the configuration of the
            moment, a fault. A link with collision geometry is held to
            max_contact_surface_distance. [m]
        max_contact_surface_distance: A contact point on the contacts topic farther than this from
            its own link's surface (the URDF's collision shapes of that link), or inside it deeper
            than this, is rejected (another finger's contact, a wrong link, a wrong frame); in the
            cycle, a fault. 5 mm covers a soft pad's compression and the collision shape's fit to
            it (1-2 mm each) and the fingers' kinematic error (0.01 rad over 0.1 m: 1 mm), and is
            well under a fingertip's radius (Allegro: 12 mm). With the scenario's object, the point
            may also lie no farther than uncertainty.pose plus this from the object's surface at
            the pose in use. [m]
        max_torque_rate: A certified command farther from the command in force than this rate
            allows since that command (at most command_period) is published as a step of at most
            this rate towards it (the rate rule, docs/node.md: flapping contacts or gravity cannot
            chatter the motors). At least 1 N m/s: a change of d N m is reached within d seconds.
            [N m/s]
        command_period: The joint states' nominal period: a step of the rate rule is at most
            max_torque_rate times the time since the command in force, and never more than
            max_torque_rate times this, however long the gap (a loop slowed by a flood cannot take
            bigger steps). [s]
        gravity_norm_bounds: [low, high]: gravity on the topic, and the gravity parameter, must
            have a norm in this range (a hand on Earth: 9.81); [0.0, 15.0] allows zero gravity
            (space, a test). [m/s^2]
        max_gravity_rate: The gravity in use moves towards each accepted gravity message at most
            this fast (a wrist turning at 10 rad/s: 98 m/s^3; the rate rule, docs/node.md). [m/s^3]
        imu_timeout_periods: (``imu.timeout_periods``) An IMU reading is fresh for this many of the
            IMU's measured periods, within imu.timeout_bounds (before a period is measured: the
            upper bound).
        imu_timeout_bounds: (``imu.timeout_bounds``) [low, high]: the IMU's freshness stays in this
            range (at 1 kHz, 5 periods are 5 ms; at 200 Hz, 25 ms). [s]
        imu_max_specific_force: (``imu.max_specific_force``) An IMU reading whose specific force's
            norm exceeds this is rejected (about 6 g: a hand that accelerates more is not holding
            anything). [m/s^2]
        imu_max_angular_velocity: (``imu.max_angular_velocity``) An IMU reading whose angular
            velocity's norm exceeds this is rejected. [rad/s]
        imu_max_arm_acceleration: (``imu.max_arm_acceleration``) An IMU reading whose specific
            force implies an arm acceleration |g_app - g_ref| above this is refused: g_ref is
            gravity (the scenario's, the gravity topic's) with its direction turned as the IMU's
            own angular velocity allows (about 2 g: the 2 g the simulation's robustness grid shakes
            the hand with pass, a still hand told 1.9 g sideways does not; docs/node.md,
            "Cross-checks and the one rate rule"). [m/s^2]
        imu_turn_tolerance: (``imu.turn_tolerance``) The reference gravity's direction follows the
            IMU's apparent gravity turning at most |omega| plus this (a gyro's bias, an
            acceleration held for long). [rad/s]
        imu_max_angular_acceleration: (``imu.max_angular_acceleration``) An IMU reading whose
            angular velocity changed faster than this since the reading before it (refused or not)
            is refused, and so are the readings after it until the rate has kept this for
            imu.timeout_bounds' upper bound: angular-rate chatter never reaches the filtered
            derivative and the inertial wrench. [rad/s^2]
        imu_angular_filter: (``imu.angular_filter``) Time constant of the low-pass on the
            derivative of the IMU's angular velocity (the base's angular acceleration). [s]
        contact_geometry: (``contact_geometry.enabled``) Find the contacts from geometry every
            cycle (the scenario needs an object): the candidate links within
            contact_geometry.tolerance of the object at the joint state and the object's pose
            (object_pose, else the scenario's) touch it, their points and inward normals computed
            (rolling tips); the set may change between cycles (docs/node.md, "Contacts from
            geometry"). Off: the scenario's contacts fixed in their links. Contacts received on the
            contacts topic are used instead.
        contact_release: (``contact_geometry.release``) A link in the set leaves it when its
            distance exceeds this many tolerances (hysteresis: a tip at the tolerance does not
            flicker at 1 kHz).
        object_pose_timeout: (``object_pose.timeout``) Once an object pose arrived, older than this
            stops commands (a fault); 0, never stale. [s]
        object_pose_max_offset: (``object_pose.max_offset``) An object pose whose position is
            farther than this from the scenario's (base frame, at the joint state of the moment) is
            rejected, at receipt and in the cycle. 0 (the default): follows the stated uncertainty,
            uncertainty.pose (at least 1 mm): the friction margin covers a pose that far off, no
            farther. [m]
        effort_estimation: (``effort_estimation.enabled``) Estimate the load the hand holds from
            joint_states' effort (least squares through J^T and G, g(q) taken out) and add to the
            planned load a bounded integral correction towards it (docs/node.md, "Load from
            efforts"). Needs the scenario's object and gravity; a driver that reports no effort
            (empty or NaN): off, said once.
        effort_time_constant: (``effort_estimation.time_constant``) Time constant T of the integral
            action on the estimated load. [s]
        effort_filter: (``effort_estimation.filter``) Time constant of the low-pass on the
            estimated load. [s]
        effort_mass_only: (``effort_estimation.mass_only``) Correct only the mass: a mass error
            from the force error along the apparent gravity, the correction that mass times the
            apparent gravity (one number, far less noisy, and right through a shake); false, the
            whole wrench (an unmodelled push or moment too).
        effort_max_load_ratio: (``effort_estimation.max_load_ratio``) The correction's force is at
            most this times the scenario's weight, its moment that force times the farthest
            contact's distance from the object origin (mass_only: the mass error at most this times
            the scenario's mass).
        effort_report: (``effort_estimation.effort_report``) What joint_states' effort is. applied:
            the torque each joint applies (current sensing, or a driver that reports its command
            plus its impedance); commanded: the node's own last command (the Allegro V5's driver),
            then the applied torque is taken as effort + driver_stiffness (driver_reference - q).
        effort_driver_stiffness: (``effort_estimation.driver_stiffness``) The driver's joint
            stiffness Kp, every joint (effort_report commanded: needed, > 0; applied: unused).
            [N m/rad]
        effort_driver_reference: (``effort_estimation.driver_reference``) The joint positions the
            driver's impedance holds, command order (effort_report commanded); empty: the
            scenario's grasp.joint_positions. [rad]
        effort_max_object_speed: (``effort_estimation.max_object_speed``) The gate: while the
            object moves faster than this (the fastest contact point under the object's motion that
            the fingertips give, its slope over speed_window), the correction is frozen at its
            value before the motion and the estimate starts again once the object is still. [m/s]
        effort_speed_window: (``effort_estimation.speed_window``) The gate's window: the object's
            speed is the least-squares slope of its displacement over this long (longer: less
            encoder noise, a later freeze, undone by holding the correction at its value this long
            before). [s]
        effort_max_residual: (``effort_estimation.max_residual``) The gate: while a fingertip is
            farther than this from the rigid motion of the object since the grasp's start (a slip,
            a roll, the object not where the scenario says), the correction is frozen. [m]
        tactile_source: (``tactile.source``) The fingertips' normal forces (docs/node.md, "Tactile
            input"): none (the default), array (std_msgs/Float32MultiArray on the tactile topic,
            entry i on the link tactile.links[i]: the Allegro V5 Sense's 16 values) or wrench
            (geometry_msgs/WrenchStamped on tactile_wrench, one link per message, frame_id the
            link, the force the link applies to the object in its axes). Used for contact-loss
            reports and the measured friction usage; never for the command's certificate.
        tactile_links: (``tactile.links``) array: the link of each entry, in order (an empty
            string: an entry not used, e.g. the V5 Sense's palm and phalanx pads); a message of
            another length is rejected. wrench: the links that carry a sensor (empty: any link of
            the hand).
        tactile_scale: (``tactile.scale``) Newtons per unit of an array entry (1: the entries are
            newtons). The V5 Sense's values are uncalibrated pressure readings: calibrate against a
            known load. [N per unit]
        tactile_timeout: (``tactile.timeout``) A link's reading older than this is not used (its
            usage and contact-loss checks say stale). [s]
        tactile_required: (``tactile.required``) With a tactile source: no fresh reading of every
            mapped link (none yet, or older than tactile.timeout) is a stale input, a fault
            (commands stop, then the fault policy). False: the node commands on and says tactile
            stale on /diagnostics.
        tactile_max_force: (``tactile.max_force``) A tactile message with a normal force above this
            (after tactile.scale) is rejected (a fingertip of the hands this package drives never
            carries 50 N). [N]
        tactile_negative_tolerance: (``tactile.negative_tolerance``) A normal force below minus
            this is rejected (a sensor cannot pull); one between is read as zero (offset noise).
            [N]
        tactile_loss_ratio: (``tactile.loss_ratio``) A planned contact whose fresh measured normal
            force is below this times the planned one (zero included) is reported lost on
            /diagnostics (tactile.lost: a slip or a finger off the object).
        object_loop: (``object_loop.enabled``) The object loop (docs/node.md, "The object loop"):
            the object's displacement and rotation from the fingertips (from a reference taken once
            the hand has settled) push back through the grasp, w_r = -(K e + D edot + Ki
            integral(e)), added to what the hand applies; the load planned and certified is the
            scenario's less w_r. Needs the scenario's object and gravity (the weight bounds w_r).
        loop_stiffness: (``object_loop.stiffness``) K on the object's displacement: the force that
            pushes a sagging object back before the integral has caught up (600 N/m: 0.6 N at 1
            mm). [N/m]
        loop_rotational_stiffness: (``object_loop.rotational_stiffness``) K on the object's
            rotation (0 by default, docs/node.md "The object loop"). [N m/rad]
        loop_damping: (``object_loop.damping``) D on the object's velocity (from the fingertips,
            low-passed): damps what K and Ki start; more amplifies encoder noise. [N s/m]
        loop_rotational_damping: (``object_loop.rotational_damping``) D on the object's angular
            velocity. [N m s/rad]
        loop_integral: (``object_loop.integral``) Ki on the integrated displacement: takes over a
            load the model misses (a heavier object, a push) so that the object goes back to where
            it was, not only less far. [N/(m s)]
        loop_rotational_integral: (``object_loop.rotational_integral``) Ki on the integrated
            rotation (an unmodelled moment, an offset centre). [N m/(rad s)]
        loop_max_integral_ratio: (``object_loop.max_integral_ratio``) The integral's force is at
            most this times the scenario's weight, its moment that force times the farthest
            contact's distance from the object origin (the load error the loop may take over for
            good).
        loop_max_force_ratio: (``object_loop.max_force_ratio``) The whole restoring force's bound
            over the scenario's weight (moment likewise).
        loop_settle_time: (``object_loop.settle_time``) The reference (where the object should
            stay) is re-taken at every cycle for this long after the loop starts, is turned on, the
            contact set changes or the joint states come back after a gap; then the loop pushes.
            [s]
        loop_velocity_filter: (``object_loop.velocity_filter``) Time constant of the low-pass on
            the error's rate (edot). [s]
        loop_unwind_time: (``object_loop.unwind_time``) After a cycle without a certified command
            or with a joint at its torque limit, the integral decays with this time constant
            (anti-windup). [s]
        loop_slip_residual: (``object_loop.slip_residual``) A contact whose distance from the
            object's rigid motion rose this far lately (object_loop.slip_memory) slips: the
            integral is frozen (the error is no motion the grasp can undo); the squeeze's usage
            from slip evidence is this distance's fraction. [m]
        loop_slip_memory: (``object_loop.slip_memory``) The time constant of the low-pass a
            contact's residual is compared with: a slip counts for about this long, then the
            squeeze may relax. [s]
        loop_squeeze: (``squeeze.enabled``) The squeeze that follows friction (with
            object_loop.enabled): the minimum normal force rises while a contact's measured
            friction usage is above squeeze.raise_at, falls back to the scenario's below
            squeeze.relax_at, within the torque limits.
        loop_raise_at: (``squeeze.raise_at``) The friction usage (1 at the cone) above which the
            squeeze rises.
        loop_relax_at: (``squeeze.relax_at``) The friction usage below which the squeeze relaxes.
        loop_rate: (``squeeze.rate``) How fast the minimum normal force rises. [N/s]
        loop_relax_rate: (``squeeze.relax_rate``) How fast it relaxes (slower than it rises, so
            that the next peak of a shake finds the squeeze still there). [N/s]
        loop_max_normal_force: (``squeeze.max_normal_force``) The squeeze's ceiling on the minimum
            normal force. [N]
        loop_usage_timeout: (``squeeze.usage_timeout``) A friction usage measured by a source
            (tactile) older than this is not used: the slip evidence is. [s]
        uncertainty_pose: (``uncertainty.pose``) Contact position / object pose uncertainty (0.002:
            2 mm): tilts a normal by pose/(R + r), R the scenario's object's radius (a box's flat
            face: no tilt), r uncertainty.tip_radius. It also bounds how far an object pose may be
            from where the fingertips place the object, and a contact point from the object's
            surface (at least 1 mm: docs/node.md, "Contacts and object pose against the hand"). [m]
        joint_limit_tolerance: A joint state with a used position beyond its joint's URDF limits by
            more than this is rejected. [rad or m]
        stamp_future_tolerance: A header stamp more than this ahead of the node's clock is
            rejected. [s]
        cycle_budget: A cycle that takes longer publishes nothing (overrun, a fault); its solvers
            stop by it (or by joint_state_timeout if smaller). [s]
        method: (``solver.method``) tau-qp (the paper's N-gon) or tau-qp-adaptive (the exact-cone
            optimum from QPs with a certified gap to it, docs/adaptive.md; needs DAQP; warm across
            cycles when solver.warm_start; solver.backend is then its fallback polygon's solver;
            slower than tau-qp, docs/adaptive.md); the ~/solve JSON carries its bounds.
        compiled: (``solver.compiled``) Run the cycle compiled (maps, build, DAQP or ProxSuite
            solve and certificate in C++, src/fast_cycle.hpp, docs/design.md section 2.6) where it
            applies: tau-qp, sum-of-squares, DAQP or ProxSuite, A = [G; J^T] of full column rank.
            Elsewhere, and on any answer it cannot certify, the Python cycle answers (diagnostics
            solver.compiled says which and why); false, the Python cycle always.
        certificate_tolerance: Tolerance of the certificate on every residual. [SI]
        command_interface: What the node publishes, in its driver's units (docs/node.md, Command
            interfaces): effort (joint torques [N m], std_msgs/Float64MultiArray on
            effort_commands); position (q_hold + tau / position.stiffness [rad], Float64MultiArray
            on position_commands); current (tau / (current.torque_constant current.gear_ratio) [A],
            Float64MultiArray on current_commands); hybrid (sensor_msgs/JointState on
            hybrid_commands: position q_hold, velocity 0, effort tau, for a driver's PD with
            hybrid.kp and hybrid.kd). Every one certifies the same torque tau (+ g(q)).
        position_stiffness: (``position.stiffness``) The position servo's stiffness K: the torque
            it produces per radian of position error, one value for every joint or one per joint,
            each > 0. Required by command_interface position. [N m/rad]
        current_torque_constant: (``current.torque_constant``) The motor's torque constant k_t (at
            the motor shaft), one value for every joint or one per joint, each > 0. Required by
            command_interface current. [N m/A]
        current_gear_ratio: (``current.gear_ratio``) Joint torque over motor torque (the gear ratio
            times its efficiency), one value for every joint or one per joint, each > 0; [1.0] when
            current.torque_constant is already the joint's.
        current_limit: (``current.limit``) The driver's current limit, one value for every joint or
            one per joint, each > 0: a command whose current would exceed it is a fault (not
            published), not a clip. Required by command_interface current. [A]
        hybrid_kp: (``hybrid.kp``) The driver's PD stiffness around the commanded position q_hold,
            one value for every joint or one per joint, each > 0 (the driver must use the same).
            Required by command_interface hybrid. [N m/rad]
        hybrid_kd: (``hybrid.kd``) The driver's PD damping towards the commanded velocity 0, one
            value for every joint or one per joint, each >= 0 (the driver must use the same).
            Required by command_interface hybrid. [N m s/rad]
    """

    gravity_compensation: bool = False
    hold_object: bool = True
    gravity: tuple = (0.0, 0.0, -9.81)
    joint_state_timeout: float = 0.1
    contacts_timeout: float = 0.5
    wrench_timeout: float = 0.5
    gravity_timeout: float = 0.5
    hold_time: float = 0.1
    fault_policy: str = 'hold'
    max_message_bytes: int = 65536
    max_joint_state_entries: int = 256
    max_wrench_force: float = 1000.0
    max_wrench_torque: float = 100.0
    max_contact_distance: float = 1.0
    max_contact_link_distance: float = 0.05
    max_contact_surface_distance: float = 0.005
    max_torque_rate: float = 20.0
    command_period: float = 0.005
    gravity_norm_bounds: tuple = (5.0, 15.0)
    max_gravity_rate: float = 100.0
    imu_timeout_periods: float = 5.0
    imu_timeout_bounds: tuple = (0.005, 0.05)
    imu_max_specific_force: float = 60.0
    imu_max_angular_velocity: float = 30.0
    imu_max_arm_acceleration: float = 20.0
    imu_turn_tolerance: float = 0.1
    imu_max_angular_acceleration: float = 200.0
    imu_angular_filter: float = 0.02
    contact_geometry: bool = False
    contact_release: float = 2.0
    object_pose_timeout: float = 0.5
    object_pose_max_offset: float = 0.0
    effort_estimation: bool = False
    effort_time_constant: float = 0.05
    effort_filter: float = 0.01
    effort_mass_only: bool = True
    effort_max_load_ratio: float = 0.5
    effort_report: str = 'applied'
    effort_driver_stiffness: float = 0.0
    effort_driver_reference: tuple = ()
    effort_max_object_speed: float = 0.005
    effort_speed_window: float = 0.05
    effort_max_residual: float = 0.001
    tactile_source: str = 'none'
    tactile_links: tuple = None
    tactile_scale: float = 1.0
    tactile_timeout: float = 0.1
    tactile_required: bool = False
    tactile_max_force: float = 50.0
    tactile_negative_tolerance: float = 0.05
    tactile_loss_ratio: float = 0.3
    object_loop: bool = False
    loop_stiffness: float = 600.0
    loop_rotational_stiffness: float = 0.0
    loop_damping: float = 4.0
    loop_rotational_damping: float = 0.0
    loop_integral: float = 6000.0
    loop_rotational_integral: float = 0.0
    loop_max_integral_ratio: float = 0.6
    loop_max_force_ratio: float = 1.0
    loop_settle_time: float = 0.2
    loop_velocity_filter: float = 0.01
    loop_unwind_time: float = 0.1
    loop_slip_residual: float = 0.001
    loop_slip_memory: float = 0.2
    loop_squeeze: bool = False
    loop_raise_at: float = 0.5
    loop_relax_at: float = 0.2
    loop_rate: float = 2.0
    loop_relax_rate: float = 0.5
    loop_max_normal_force: float = 1.0
    loop_usage_timeout: float = 0.05
    uncertainty_pose: float = 0.0
    joint_limit_tolerance: float = 0.1
    stamp_future_tolerance: float = 0.5
    cycle_budget: float = 0.05
    method: str = 'tau-qp'
    compiled: bool = True
    certificate_tolerance: float = 1e-06
    command_interface: str = 'effort'
    position_stiffness: tuple = None
    current_torque_constant: tuple = None
    current_gear_ratio: tuple = (1.0,)
    current_limit: tuple = None
    hybrid_kp: tuple = None
    hybrid_kd: tuple = None


@dataclass(frozen=True)
class ParamsImu:
    """
    The ``imu.*`` parameters.

    Attributes:
        enabled: Subscribe to the imu topic (sensor_msgs/Imu of the hand's base: specific force and
            angular velocity, in the base frame or any frame tf2 resolves): while a reading is
            fresh, g(q) and the scenario's load take the apparent gravity -R f, and the load the
            object's inertial wrench from the base's angular velocity and its filtered derivative
            (docs/node.md, "Moving base"). A stale or rejected IMU: the scenario's (or the gravity
            topic's) gravity again, said in diagnostics.
        timeout_periods: An IMU reading is fresh for this many of the IMU's measured periods,
            within imu.timeout_bounds (before a period is measured: the upper bound).
        timeout_bounds: [low, high]: the IMU's freshness stays in this range (at 1 kHz, 5 periods
            are 5 ms; at 200 Hz, 25 ms). [s]
        max_specific_force: An IMU reading whose specific force's norm exceeds this is rejected
            (about 6 g: a hand that accelerates more is not holding anything). [m/s^2]
        max_angular_velocity: An IMU reading whose angular velocity's norm exceeds this is
            rejected. [rad/s]
        max_arm_acceleration: An IMU reading whose specific force implies an arm acceleration
            |g_app - g_ref| above this is refused: g_ref is gravity (the scenario's, the gravity
            topic's) with its direction turned as the IMU's own angular velocity allows (about 2 g:
            the 2 g the simulation's robustness grid shakes the hand with pass, a still hand told
            1.9 g sideways does not; docs/node.md, "Cross-checks and the one rate rule"). [m/s^2]
        turn_tolerance: The reference gravity's direction follows the IMU's apparent gravity
            turning at most |omega| plus this (a gyro's bias, an acceleration held for long).
            [rad/s]
        max_angular_acceleration: An IMU reading whose angular velocity changed faster than this
            since the reading before it (refused or not) is refused, and so are the readings after
            it until the rate has kept this for imu.timeout_bounds' upper bound: angular-rate
            chatter never reaches the filtered derivative and the inertial wrench. [rad/s^2]
        angular_filter: Time constant of the low-pass on the derivative of the IMU's angular
            velocity (the base's angular acceleration). [s]
    """

    enabled: bool | None
    timeout_periods: float | None
    timeout_bounds: tuple | None
    max_specific_force: float | None
    max_angular_velocity: float | None
    max_arm_acceleration: float | None
    turn_tolerance: float | None
    max_angular_acceleration: float | None
    angular_filter: float | None


@dataclass(frozen=True)
class ParamsContactGeometry:
    """
    The ``contact_geometry.*`` parameters.

    Attributes:
        enabled: Find the contacts from geometry every cycle (the scenario needs an object): the
            candidate links within contact_geometry.tolerance of the object at the joint state and
            the object's pose (object_pose, else the scenario's) touch it, their points and inward
            normals computed (rolling tips); the set may change between cycles (docs/node.md,
            "Contacts from geometry"). Off: the scenario's contacts fixed in their links. Contacts
            received on the contacts topic are used instead.
        links: The candidate links; empty: the scenario's contact links; [auto]: every link with
            collision geometry that a joint moves.
        tolerance: A candidate link enters the contact set when its signed distance to the object
            is at most this. [m]
        release: A link in the set leaves it when its distance exceeds this many tolerances
            (hysteresis: a tip at the tolerance does not flicker at 1 kHz).
    """

    enabled: bool | None
    links: tuple | None
    tolerance: float | None
    release: float | None


@dataclass(frozen=True)
class ParamsObjectPose:
    """
    The ``object_pose.*`` parameters.

    Attributes:
        timeout: Once an object pose arrived, older than this stops commands (a fault); 0, never
            stale. [s]
        max_offset: An object pose whose position is farther than this from the scenario's (base
            frame, at the joint state of the moment) is rejected, at receipt and in the cycle. 0
            (the default): follows the stated uncertainty, uncertainty.pose (at least 1 mm): the
            friction margin covers a pose that far off, no farther. [m]
    """

    timeout: float | None
    max_offset: float | None


@dataclass(frozen=True)
class ParamsEffortEstimation:
    """
    The ``effort_estimation.*`` parameters.

    Attributes:
        enabled: Estimate the load the hand holds from joint_states' effort (least squares through
            J^T and G, g(q) taken out) and add to the planned load a bounded integral correction
            towards it (docs/node.md, "Load from efforts"). Needs the scenario's object and
            gravity; a driver that reports no effort (empty or NaN): off, said once.
        time_constant: Time constant T of the integral action on the estimated load. [s]
        filter: Time constant of the low-pass on the estimated load. [s]
        mass_only: Correct only the mass: a mass error from the force error along the apparent
            gravity, the correction that mass times the apparent gravity (one number, far less
            noisy, and right through a shake); false, the whole wrench (an unmodelled push or
            moment too).
        max_load_ratio: The correction's force is at most this times the scenario's weight, its
            moment that force times the farthest contact's distance from the object origin
            (mass_only: the mass error at most this times the scenario's mass).
        effort_report: What joint_states' effort is. applied: the torque each joint applies
            (current sensing, or a driver that reports its command plus its impedance); commanded:
            the node's own last command (the Allegro V5's driver), then the applied torque is taken
            as effort + driver_stiffness (driver_reference - q).
        driver_stiffness: The driver's joint stiffness Kp, every joint (effort_report commanded:
            needed, > 0; applied: unused). [N m/rad]
        driver_reference: The joint positions the driver's impedance holds, command order
            (effort_report commanded); empty: the scenario's grasp.joint_positions. [rad]
        max_object_speed: The gate: while the object moves faster than this (the fastest contact
            point under the object's motion that the fingertips give, its slope over speed_window),
            the correction is frozen at its value before the motion and the estimate starts again
            once the object is still. [m/s]
        speed_window: The gate's window: the object's speed is the least-squares slope of its
            displacement over this long (longer: less encoder noise, a later freeze, undone by
            holding the correction at its value this long before). [s]
        max_residual: The gate: while a fingertip is farther than this from the rigid motion of the
            object since the grasp's start (a slip, a roll, the object not where the scenario
            says), the correction is frozen. [m]
    """

    enabled: bool | None
    time_constant: float | None
    filter: float | None  # noqa: A003 -- the parameter's name
    mass_only: bool | None
    max_load_ratio: float | None
    effort_report: str | None
    driver_stiffness: float | None
    driver_reference: tuple | None
    max_object_speed: float | None
    speed_window: float | None
    max_residual: float | None


@dataclass(frozen=True)
class ParamsTactile:
    """
    The ``tactile.*`` parameters.

    Attributes:
        source: The fingertips' normal forces (docs/node.md, "Tactile input"): none (the default),
            array (std_msgs/Float32MultiArray on the tactile topic, entry i on the link
            tactile.links[i]: the Allegro V5 Sense's 16 values) or wrench
            (geometry_msgs/WrenchStamped on tactile_wrench, one link per message, frame_id the
            link, the force the link applies to the object in its axes). Used for contact-loss
            reports and the measured friction usage; never for the command's certificate.
        links: array: the link of each entry, in order (an empty string: an entry not used, e.g.
            the V5 Sense's palm and phalanx pads); a message of another length is rejected. wrench:
            the links that carry a sensor (empty: any link of the hand).
        scale: Newtons per unit of an array entry (1: the entries are newtons). The V5 Sense's
            values are uncalibrated pressure readings: calibrate against a known load. [N per unit]
        timeout: A link's reading older than this is not used (its usage and contact-loss checks
            say stale). [s]
        required: With a tactile source: no fresh reading of every mapped link (none yet, or older
            than tactile.timeout) is a stale input, a fault (commands stop, then the fault policy).
            False: the node commands on and says tactile stale on /diagnostics.
        max_force: A tactile message with a normal force above this (after tactile.scale) is
            rejected (a fingertip of the hands this package drives never carries 50 N). [N]
        negative_tolerance: A normal force below minus this is rejected (a sensor cannot pull); one
            between is read as zero (offset noise). [N]
        loss_ratio: A planned contact whose fresh measured normal force is below this times the
            planned one (zero included) is reported lost on /diagnostics (tactile.lost: a slip or a
            finger off the object).
    """

    source: str | None
    links: tuple | None
    scale: float | None
    timeout: float | None
    required: bool | None
    max_force: float | None
    negative_tolerance: float | None
    loss_ratio: float | None


@dataclass(frozen=True)
class ParamsObjectLoop:
    """
    The ``object_loop.*`` parameters.

    Attributes:
        enabled: The object loop (docs/node.md, "The object loop"): the object's displacement and
            rotation from the fingertips (from a reference taken once the hand has settled) push
            back through the grasp, w_r = -(K e + D edot + Ki integral(e)), added to what the hand
            applies; the load planned and certified is the scenario's less w_r. Needs the
            scenario's object and gravity (the weight bounds w_r).
        stiffness: K on the object's displacement: the force that pushes a sagging object back
            before the integral has caught up (600 N/m: 0.6 N at 1 mm). [N/m]
        rotational_stiffness: K on the object's rotation (0 by default, docs/node.md "The object
            loop"). [N m/rad]
        damping: D on the object's velocity (from the fingertips, low-passed): damps what K and Ki
            start; more amplifies encoder noise. [N s/m]
        rotational_damping: D on the object's angular velocity. [N m s/rad]
        integral: Ki on the integrated displacement: takes over a load the model misses (a heavier
            object, a push) so that the object goes back to where it was, not only less far.
            [N/(m s)]
        rotational_integral: Ki on the integrated rotation (an unmodelled moment, an offset
            centre). [N m/(rad s)]
        max_integral_ratio: The integral's force is at most this times the scenario's weight, its
            moment that force times the farthest contact's distance from the object origin (the
            load error the loop may take over for good).
        max_force_ratio: The whole restoring force's bound over the scenario's weight (moment
            likewise).
        settle_time: The reference (where the object should stay) is re-taken at every cycle for
            this long after the loop starts, is turned on, the contact set changes or the joint
            states come back after a gap; then the loop pushes. [s]
        velocity_filter: Time constant of the low-pass on the error's rate (edot). [s]
        unwind_time: After a cycle without a certified command or with a joint at its torque limit,
            the integral decays with this time constant (anti-windup). [s]
        slip_residual: A contact whose distance from the object's rigid motion rose this far lately
            (object_loop.slip_memory) slips: the integral is frozen (the error is no motion the
            grasp can undo); the squeeze's usage from slip evidence is this distance's fraction.
            [m]
        slip_memory: The time constant of the low-pass a contact's residual is compared with: a
            slip counts for about this long, then the squeeze may relax. [s]
    """

    enabled: bool | None
    stiffness: float | None
    rotational_stiffness: float | None
    damping: float | None
    rotational_damping: float | None
    integral: float | None
    rotational_integral: float | None
    max_integral_ratio: float | None
    max_force_ratio: float | None
    settle_time: float | None
    velocity_filter: float | None
    unwind_time: float | None
    slip_residual: float | None
    slip_memory: float | None


@dataclass(frozen=True)
class ParamsSqueeze:
    """
    The ``squeeze.*`` parameters.

    Attributes:
        enabled: The squeeze that follows friction (with object_loop.enabled): the minimum normal
            force rises while a contact's measured friction usage is above squeeze.raise_at, falls
            back to the scenario's below squeeze.relax_at, within the torque limits.
        raise_at: The friction usage (1 at the cone) above which the squeeze rises.
        relax_at: The friction usage below which the squeeze relaxes.
        rate: How fast the minimum normal force rises. [N/s]
        relax_rate: How fast it relaxes (slower than it rises, so that the next peak of a shake
            finds the squeeze still there). [N/s]
        max_normal_force: The squeeze's ceiling on the minimum normal force. [N]
        usage_timeout: A friction usage measured by a source (tactile) older than this is not used:
            the slip evidence is. [s]
    """

    enabled: bool | None
    raise_at: float | None
    relax_at: float | None
    rate: float | None
    relax_rate: float | None
    max_normal_force: float | None
    usage_timeout: float | None


@dataclass(frozen=True)
class ParamsUncertainty:
    """
    The ``uncertainty.*`` parameters.

    Attributes:
        friction: Friction uncertainty, a fraction (0.2: mu may be 20% lower). With
            uncertainty.pose, sets the friction margin k = mu/mu_eff - 1, mu_eff = tan(atan(mu (1 -
            friction)) - pose/(R + r)); the larger of it and friction_margin is planned
            (docs/node.md, "Margin from stated uncertainty").
        pose: Contact position / object pose uncertainty (0.002: 2 mm): tilts a normal by pose/(R +
            r), R the scenario's object's radius (a box's flat face: no tilt), r
            uncertainty.tip_radius. It also bounds how far an object pose may be from where the
            fingertips place the object, and a contact point from the object's surface (at least 1
            mm: docs/node.md, "Contacts and object pose against the hand"). [m]
        tip_radius: The fingertips' radius r in the tilt pose/(R + r) (Allegro's, 12 mm). [m]
    """

    friction: float | None
    pose: float | None
    tip_radius: float | None


@dataclass(frozen=True)
class ParamsSolver:
    """
    The ``solver.*`` parameters.

    Attributes:
        method: tau-qp (the paper's N-gon) or tau-qp-adaptive (the exact-cone optimum from QPs with
            a certified gap to it, docs/adaptive.md; needs DAQP; warm across cycles when
            solver.warm_start; solver.backend is then its fallback polygon's solver; slower than
            tau-qp, docs/adaptive.md); the ~/solve JSON carries its bounds.
        backend: QP backend: proxsuite, daqp or quadprog (grasps without internal-force variables
            only); every result is certified whichever solves it.
        fallback: Backend asked in the same cycle when solver.backend gives nothing certifiable
            (none: no second try); its answer is certified the same way and counted (diagnostics
            solver.fallback_solves).
        warm_start: Start each solve from the previous cycle's (ProxSuite: its result,
            preconditioner kept; DAQP: its active set); an answer that is not solved, fails the KKT
            check or is not certified is redone cold in the same cycle and counted (diagnostics
            solver.warm_start_fallbacks); no effect on quadprog; the ~/solve service always solves
            cold.
        compiled: Run the cycle compiled (maps, build, DAQP or ProxSuite solve and certificate in
            C++, src/fast_cycle.hpp, docs/design.md section 2.6) where it applies: tau-qp,
            sum-of-squares, DAQP or ProxSuite, A = [G; J^T] of full column rank. Elsewhere, and on
            any answer it cannot certify, the Python cycle answers (diagnostics solver.compiled
            says which and why); false, the Python cycle always.
        eps_abs: Solver absolute tolerance (ProxSuite eps_abs, DAQP primal_tol).
        max_iter: Solver iteration cap (ProxSuite outer, DAQP).
        max_iter_in: ProxSuite inner iteration cap; one outer iteration, up to this many inner
            ones, is how far a solve can run past its budget.
    """

    method: str | None
    backend: str | None
    fallback: str | None
    warm_start: bool | None
    compiled: bool | None
    eps_abs: float | None
    max_iter: int | None
    max_iter_in: int | None


@dataclass(frozen=True)
class ParamsPosition:
    """
    The ``position.*`` parameters.

    Attributes:
        stiffness: The position servo's stiffness K: the torque it produces per radian of position
            error, one value for every joint or one per joint, each > 0. Required by
            command_interface position. [N m/rad]
    """

    stiffness: tuple | None


@dataclass(frozen=True)
class ParamsCurrent:
    """
    The ``current.*`` parameters.

    Attributes:
        torque_constant: The motor's torque constant k_t (at the motor shaft), one value for every
            joint or one per joint, each > 0. Required by command_interface current. [N m/A]
        gear_ratio: Joint torque over motor torque (the gear ratio times its efficiency), one value
            for every joint or one per joint, each > 0; [1.0] when current.torque_constant is
            already the joint's.
        limit: The driver's current limit, one value for every joint or one per joint, each > 0: a
            command whose current would exceed it is a fault (not published), not a clip. Required
            by command_interface current. [A]
    """

    torque_constant: tuple | None
    gear_ratio: tuple | None
    limit: tuple | None


@dataclass(frozen=True)
class ParamsHybrid:
    """
    The ``hybrid.*`` parameters.

    Attributes:
        kp: The driver's PD stiffness around the commanded position q_hold, one value for every
            joint or one per joint, each > 0 (the driver must use the same). Required by
            command_interface hybrid. [N m/rad]
        kd: The driver's PD damping towards the commanded velocity 0, one value for every joint or
            one per joint, each >= 0 (the driver must use the same). Required by command_interface
            hybrid. [N m s/rad]
    """

    kp: tuple | None
    kd: tuple | None


@dataclass(frozen=True)
class Params:
    """
    The frozen snapshot of every parameter, one class per namespace.

    Attributes:
        scenario: Scenario file (docs/design.md section 4): hand, default contacts and load. A
            path, or the name of a bundled file in the package's config/ (allegro_right.yaml).
            Required.
        robot_description: URDF document of the hand (the ROS convention), or a path to a URDF
            file; empty: the URDF published on robot_description_topic if that is set, else the
            scenario's hand.urdf.
        robot_description_topic: A topic to take the URDF from when robot_description is empty
            (std_msgs/String, reliable, transient local, e.g. robot_description, as
            robot_state_publisher publishes it; relative names resolve in the node's namespace);
            '': none. Waited for at start (the managed node: in configure) up to
            robot_description_timeout.
        robot_description_timeout: How long the node waits for the URDF on robot_description_topic
            before it gives up, naming the topic. [s]
        name_map: The scenario's joint and frame names to the URDF's, as SCENARIO_NAME=URDF_NAME
            entries (one '=' each, at most 1024, one to one), over the scenario's hand.name_map:
            applied before any name is checked against the URDF (docs/design.md section 4.1).
        joints: Actuated joints in command order, the URDF's names (the scenario's after the name
            map).
        object_origin: Object origin c in the base frame. [m]
        mu_tangential: Tangential friction coefficient mu1.
        mu_torsional: Torsional friction coefficient mu2. [m]
        polygon_sides: Sides N of the inscribed friction polygon.
        min_normal_force: Minimum normal force f_min per contact. [N]
        torque_limits: |command_i| <= torque_limits[i], per joint, each > 0 and at most the joint's
            URDF effort limit (the scenario's limit where the URDF gives none) unless
            torque_limits_above_urdf; a change acts on the command in force at once (docs/node.md,
            Faults). [N m]
        torque_limits_above_urdf: Allow torque_limits above the URDF's effort limits, up to 1e4 N
            m.
        weights: Objective weights W (diagonal), per joint, each in [1e-6, 1e6], the largest at
            most 1e6 times the smallest (W's condition number bounds how hard the QP is).
        friction_margin: Friction margin k: plan inside the cone of mu/(1+k), so that the commanded
            wrenches hold with up to (1+k) times less friction (docs/planner.md).
        objective: sum-of-squares (the paper's) or min-max (max |tau_i + g_i| / limit_i, an LP,
            then the sum of squares among its optima: slower; docs/planner.md); min-max needs
            solver.method tau-qp.
        gravity_compensation: Add the fingers' own gravity torques g(q); the torque limits then
            bound tau + g(q).
        hold_object: false: the hand holds no object: no grasp is solved, the command is g(q) alone
            (finger gravity compensation; zero torques without gravity_compensation), the contacts'
            wrenches fading out by the rate rule; true again: the grasp fades in (docs/node.md, "No
            object: finger gravity compensation").
        gravity: Gravity in the base frame for g(q) and, where the scenario's load is its object's
            weight, for the load (the Allegro scenario: [9.81, 0, 0], palm down); once a message
            arrives on the gravity topic, the topic's gravity is used instead. [m/s^2]
        joint_state_timeout: Joint states older than this stop commands. [s]
        contacts_timeout: Once contacts arrived, older than this stop commands; 0, never stale. [s]
        wrench_timeout: Once a load arrived on external_wrench, older than this stops commands; 0,
            never stale. [s]
        gravity_timeout: Once gravity arrived on the gravity topic, older than this stops commands
            (a fault, as any stale input); 0, never stale. [s]
        hold_time: How long a fault may hold the last certified command before the fault policy
            applies. [s]
        fault_policy: After hold_time in a fault: hold (publish nothing, the effort controller
            keeps the last certified command) or zero (publish zero torques); docs/node.md, Faults.
        max_message_bytes: A message on joint_states, contacts, external_wrench or gravity whose
            serialized form is longer than this is rejected before it is deserialized. [bytes]
        max_joint_state_entries: A joint state with more names or positions than this is rejected
            unread.
        max_wrench_force: A load whose force norm exceeds this is rejected. [N]
        max_wrench_torque: A load whose moment norm exceeds this is rejected. [N m]
        max_contact_distance: A contact point farther than this from the base origin stops commands
            (a fault). [m]
        max_contact_link_distance: For a link without collision geometry in the URDF: a contact
            point on the contacts topic farther than this from its own link's frame is rejected
            (another finger's contact, a wrong frame); in the cycle, at the configuration of the
            moment, a fault. A link with collision geometry is held to
            max_contact_surface_distance. [m]
        max_contact_surface_distance: A contact point on the contacts topic farther than this from
            its own link's surface (the URDF's collision shapes of that link), or inside it deeper
            than this, is rejected (another finger's contact, a wrong link, a wrong frame); in the
            cycle, a fault. 5 mm covers a soft pad's compression and the collision shape's fit to
            it (1-2 mm each) and the fingers' kinematic error (0.01 rad over 0.1 m: 1 mm), and is
            well under a fingertip's radius (Allegro: 12 mm). With the scenario's object, the point
            may also lie no farther than uncertainty.pose plus this from the object's surface at
            the pose in use. [m]
        max_torque_rate: A certified command farther from the command in force than this rate
            allows since that command (at most command_period) is published as a step of at most
            this rate towards it (the rate rule, docs/node.md: flapping contacts or gravity cannot
            chatter the motors). At least 1 N m/s: a change of d N m is reached within d seconds.
            [N m/s]
        command_period: The joint states' nominal period: a step of the rate rule is at most
            max_torque_rate times the time since the command in force, and never more than
            max_torque_rate times this, however long the gap (a loop slowed by a flood cannot take
            bigger steps). [s]
        gravity_norm_bounds: [low, high]: gravity on the topic, and the gravity parameter, must
            have a norm in this range (a hand on Earth: 9.81); [0.0, 15.0] allows zero gravity
            (space, a test). [m/s^2]
        max_gravity_rate: The gravity in use moves towards each accepted gravity message at most
            this fast (a wrist turning at 10 rad/s: 98 m/s^3; the rate rule, docs/node.md). [m/s^3]
        imu: the ``imu.*`` parameters.
        contact_geometry: the ``contact_geometry.*`` parameters.
        object_pose: the ``object_pose.*`` parameters.
        effort_estimation: the ``effort_estimation.*`` parameters.
        tactile: the ``tactile.*`` parameters.
        object_loop: the ``object_loop.*`` parameters.
        squeeze: the ``squeeze.*`` parameters.
        uncertainty: the ``uncertainty.*`` parameters.
        joint_limit_tolerance: A joint state with a used position beyond its joint's URDF limits by
            more than this is rejected. [rad or m]
        stamp_future_tolerance: A header stamp more than this ahead of the node's clock is
            rejected. [s]
        cycle_budget: A cycle that takes longer publishes nothing (overrun, a fault); its solvers
            stop by it (or by joint_state_timeout if smaller). [s]
        solver: the ``solver.*`` parameters.
        certificate_tolerance: Tolerance of the certificate on every residual. [SI]
        diagnostics_period: Period of /diagnostics (1 Hz, as diagnostic_updater; hardware_id is the
            hand's URDF name, e.g. allegro_hand_right). [s]
        marker_period: Period of ~/contact_wrenches; each arrow lives three periods, so the arrows
            vanish when the node stops. [s]
        watchdog_period: Period of the staleness check between joint states. [s]
        startup_check_time: At start, how long the node looks for another node of its name on the
            domain before it takes any input (discovery can take seconds); one found, exit code 2
            and one line naming it; one seen later is reported (diagnostics ERROR, a log line). [s]
        thread_priority: At start, the SCHED_FIFO priority the executables ask for the thread that
            spins the node, and for it alone (ros2_control's controller_manager asks 50 for its
            loop), with Python's thread switch interval at 0.5 ms; refused (no rtprio limit or
            CAP_SYS_NICE), a warning and normal scheduling; 0 (the default), the scheduling is left
            as it is. Off by default: it helps the 1 kHz answer rate and hurts the tails on a busy
            2-core machine (docs/node.md, The executor thread's priority).
        marker_scale: Arrow length per newton in ~/contact_wrenches. [m/N]
        age_on_sim_time: With use_sim_time, age the inputs and pace the rate rules on the ROS clock
            (simulated time) instead of the monotonic clock, for a simulation that waits for the
            node (grasp-torque-sim --lockstep). A /clock that stops then stops staleness:
            simulations only.
        publish_stamped_command: Also publish each command on ~/effort_commands_stamped
            (sensor_msgs/JointState: joints, effort, and the stamp of the joint state it was
            computed from).
        command_interface: What the node publishes, in its driver's units (docs/node.md, Command
            interfaces): effort (joint torques [N m], std_msgs/Float64MultiArray on
            effort_commands); position (q_hold + tau / position.stiffness [rad], Float64MultiArray
            on position_commands); current (tau / (current.torque_constant current.gear_ratio) [A],
            Float64MultiArray on current_commands); hybrid (sensor_msgs/JointState on
            hybrid_commands: position q_hold, velocity 0, effort tau, for a driver's PD with
            hybrid.kp and hybrid.kd). Every one certifies the same torque tau (+ g(q)).
        position: the ``position.*`` parameters.
        current: the ``current.*`` parameters.
        hybrid: the ``hybrid.*`` parameters.
    """

    scenario: str | None
    robot_description: str | None
    robot_description_topic: str | None
    robot_description_timeout: float | None
    name_map: tuple | None
    joints: tuple | None
    object_origin: tuple | None
    mu_tangential: float | None
    mu_torsional: float | None
    polygon_sides: int | None
    min_normal_force: float | None
    torque_limits: tuple | None
    torque_limits_above_urdf: bool | None
    weights: tuple | None
    friction_margin: float | None
    objective: str | None
    gravity_compensation: bool | None
    hold_object: bool | None
    gravity: tuple | None
    joint_state_timeout: float | None
    contacts_timeout: float | None
    wrench_timeout: float | None
    gravity_timeout: float | None
    hold_time: float | None
    fault_policy: str | None
    max_message_bytes: int | None
    max_joint_state_entries: int | None
    max_wrench_force: float | None
    max_wrench_torque: float | None
    max_contact_distance: float | None
    max_contact_link_distance: float | None
    max_contact_surface_distance: float | None
    max_torque_rate: float | None
    command_period: float | None
    gravity_norm_bounds: tuple | None
    max_gravity_rate: float | None
    imu: ParamsImu
    contact_geometry: ParamsContactGeometry
    object_pose: ParamsObjectPose
    effort_estimation: ParamsEffortEstimation
    tactile: ParamsTactile
    object_loop: ParamsObjectLoop
    squeeze: ParamsSqueeze
    uncertainty: ParamsUncertainty
    joint_limit_tolerance: float | None
    stamp_future_tolerance: float | None
    cycle_budget: float | None
    solver: ParamsSolver
    certificate_tolerance: float | None
    diagnostics_period: float | None
    marker_period: float | None
    watchdog_period: float | None
    startup_check_time: float | None
    thread_priority: int | None
    marker_scale: float | None
    age_on_sim_time: bool | None
    publish_stamped_command: bool | None
    command_interface: str | None
    position: ParamsPosition
    current: ParamsCurrent
    hybrid: ParamsHybrid


#: CycleConfig field -> the parameter that gives it.
CYCLE_FIELDS = {
    'gravity_compensation': 'gravity_compensation',
    'hold_object': 'hold_object',
    'gravity': 'gravity',
    'joint_state_timeout': 'joint_state_timeout',
    'contacts_timeout': 'contacts_timeout',
    'wrench_timeout': 'wrench_timeout',
    'gravity_timeout': 'gravity_timeout',
    'hold_time': 'hold_time',
    'fault_policy': 'fault_policy',
    'max_message_bytes': 'max_message_bytes',
    'max_joint_state_entries': 'max_joint_state_entries',
    'max_wrench_force': 'max_wrench_force',
    'max_wrench_torque': 'max_wrench_torque',
    'max_contact_distance': 'max_contact_distance',
    'max_contact_link_distance': 'max_contact_link_distance',
    'max_contact_surface_distance': 'max_contact_surface_distance',
    'max_torque_rate': 'max_torque_rate',
    'command_period': 'command_period',
    'gravity_norm_bounds': 'gravity_norm_bounds',
    'max_gravity_rate': 'max_gravity_rate',
    'imu_timeout_periods': 'imu.timeout_periods',
    'imu_timeout_bounds': 'imu.timeout_bounds',
    'imu_max_specific_force': 'imu.max_specific_force',
    'imu_max_angular_velocity': 'imu.max_angular_velocity',
    'imu_max_arm_acceleration': 'imu.max_arm_acceleration',
    'imu_turn_tolerance': 'imu.turn_tolerance',
    'imu_max_angular_acceleration': 'imu.max_angular_acceleration',
    'imu_angular_filter': 'imu.angular_filter',
    'contact_geometry': 'contact_geometry.enabled',
    'contact_release': 'contact_geometry.release',
    'object_pose_timeout': 'object_pose.timeout',
    'object_pose_max_offset': 'object_pose.max_offset',
    'effort_estimation': 'effort_estimation.enabled',
    'effort_time_constant': 'effort_estimation.time_constant',
    'effort_filter': 'effort_estimation.filter',
    'effort_mass_only': 'effort_estimation.mass_only',
    'effort_max_load_ratio': 'effort_estimation.max_load_ratio',
    'effort_report': 'effort_estimation.effort_report',
    'effort_driver_stiffness': 'effort_estimation.driver_stiffness',
    'effort_driver_reference': 'effort_estimation.driver_reference',
    'effort_max_object_speed': 'effort_estimation.max_object_speed',
    'effort_speed_window': 'effort_estimation.speed_window',
    'effort_max_residual': 'effort_estimation.max_residual',
    'tactile_source': 'tactile.source',
    'tactile_links': 'tactile.links',
    'tactile_scale': 'tactile.scale',
    'tactile_timeout': 'tactile.timeout',
    'tactile_required': 'tactile.required',
    'tactile_max_force': 'tactile.max_force',
    'tactile_negative_tolerance': 'tactile.negative_tolerance',
    'tactile_loss_ratio': 'tactile.loss_ratio',
    'object_loop': 'object_loop.enabled',
    'loop_stiffness': 'object_loop.stiffness',
    'loop_rotational_stiffness': 'object_loop.rotational_stiffness',
    'loop_damping': 'object_loop.damping',
    'loop_rotational_damping': 'object_loop.rotational_damping',
    'loop_integral': 'object_loop.integral',
    'loop_rotational_integral': 'object_loop.rotational_integral',
    'loop_max_integral_ratio': 'object_loop.max_integral_ratio',
    'loop_max_force_ratio': 'object_loop.max_force_ratio',
    'loop_settle_time': 'object_loop.settle_time',
    'loop_velocity_filter': 'object_loop.velocity_filter',
    'loop_unwind_time': 'object_loop.unwind_time',
    'loop_slip_residual': 'object_loop.slip_residual',
    'loop_slip_memory': 'object_loop.slip_memory',
    'loop_squeeze': 'squeeze.enabled',
    'loop_raise_at': 'squeeze.raise_at',
    'loop_relax_at': 'squeeze.relax_at',
    'loop_rate': 'squeeze.rate',
    'loop_relax_rate': 'squeeze.relax_rate',
    'loop_max_normal_force': 'squeeze.max_normal_force',
    'loop_usage_timeout': 'squeeze.usage_timeout',
    'uncertainty_pose': 'uncertainty.pose',
    'joint_limit_tolerance': 'joint_limit_tolerance',
    'stamp_future_tolerance': 'stamp_future_tolerance',
    'cycle_budget': 'cycle_budget',
    'method': 'solver.method',
    'compiled': 'solver.compiled',
    'certificate_tolerance': 'certificate_tolerance',
    'command_interface': 'command_interface',
    'position_stiffness': 'position.stiffness',
    'current_torque_constant': 'current.torque_constant',
    'current_gear_ratio': 'current.gear_ratio',
    'current_limit': 'current.limit',
    'hybrid_kp': 'hybrid.kp',
    'hybrid_kd': 'hybrid.kd',
}
