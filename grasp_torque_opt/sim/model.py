# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The MuJoCo model of a scenario: the hand from its URDF and the scenario's object.

The URDF is adapted before MuJoCo compiles it (docs/simulation.md, "The model"):

- joint ``dynamics friction`` is zeroed: example-robot-data's Allegro declares 5 to
  12 N m per joint, far above its 0.7 N m torque limits, which locks the fingers so
  that any torque "holds"; joint ``damping`` is replaced by ``joint_damping`` for
  the same reason (3 to 10 N m s/rad in that URDF, unmeasured; with it even pure
  torque control holds) -- the driver's impedance damping is added on top;
- ``balanceinertia``: some link inertias of that URDF break the triangle
  inequality (mass and centre of mass are unchanged, so g(q) is too);
- ``fusestatic`` off: otherwise the fixed ``*_tip`` links that the scenario's
  contacts name are merged away;
- visuals are discarded (their ``package://`` meshes need not resolve);
- the hand's own bodies do not collide with each other (MuJoCo's parent-child
  filter does not apply to links welded to the world, so the palm box would
  collide with the fingers' base links), only with the object.

Contacts use MuJoCo's elliptic soft-finger model (condim 4: two tangential and one
torsional friction direction) with the scenario's mu_tangential and mu_torsional,
stiff (``solref`` 2 ms instead of MuJoCo's 20 ms, with which the ball creeps out of
the bundled grasp), ``impratio`` 10 and a few noslip iterations.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
import warnings
import xml.etree.ElementTree as ET

from grasp_torque_opt.core.exceptions import GeometryWarning, InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import resolve_urdf
from grasp_torque_opt.core.meshes import resolve_meshes
from grasp_torque_opt.core.scenario import ObjectSpec, Scenario
from grasp_torque_opt.sim.robot import weld_and_couple
import mujoco
import numpy as np
import pinocchio as pin

#: Contact bits: hand geoms (type 1, affinity 2) touch the object (type 2, affinity 1) only.
_HAND_BITS, _OBJECT_BITS = (1, 2), (2, 1)
OBJECT_BODY = 'object'
#: The object's colour: orange (the picture's arrows are blue and green against it).
OBJECT_RGBA = [0.85, 0.45, 0.15, 1.0]


@dataclass(frozen=True)
class SimSettings:
    """
    How the scenario is simulated.

    Attributes:
        timestep: integration step [s] (the driver steps at 1 kHz).
        contact_timeconst: ``solref`` time constant of every contact [s].
        impratio: MuJoCo's ratio of frictional to normal constraint impedance [-].
        noslip_iterations: MuJoCo's noslip solver iterations [-].
        mu_tangential: simulated tangential friction [-]; None: the scenario's.
        mu_torsional: simulated torsional friction [m]; None: the scenario's.
        joint_damping: passive viscous damping of every joint in place of the
            URDF's [N m s/rad].
        mass: simulated object mass [kg]; None: the scenario's.
        touch: give each contact link a MuJoCo touch sensor (:func:`touch_sensors`).
    """

    timestep: float = 1e-3
    contact_timeconst: float = 0.002
    impratio: float = 10.0
    noslip_iterations: int = 5
    mu_tangential: float | None = None
    mu_torsional: float | None = None
    joint_damping: float = 0.0
    mass: float | None = None
    touch: bool = False


@dataclass(frozen=True)
class SimModel:
    """
    A compiled model and where the scenario's parts are in it.

    Attributes:
        model: the MuJoCo model (base frame = MuJoCo world).
        joints: actuated joints in command order.
        qpos_adr: their qpos addresses, shape (m,).
        dof_adr: their dof addresses, shape (m,).
        object_body: body id of the object.
        object_qpos: qpos address of the object's free joint (position, then
            quaternion w, x, y, z).
        object_dof: dof address of the object's free joint.
        contact_bodies: per scenario contact, the body id of its link.
        gravity: gravity in the base frame [m/s^2], shape (3,).
        mu_tangential: simulated tangential friction [-].
        mu_torsional: simulated torsional friction [m].
        base_rotation: the base frame's axes in MuJoCo's world (the URDF's root),
            shape (3, 3): identity unless ``hand.base_link``.
        followers: coupled joints that move, (qpos address, its target's, multiplier,
            offset): a MuJoCo joint equality holds each; the simulator starts them on it.
        touch_adr: per scenario contact, the ``sensordata`` address of its link's touch
            sensor (empty without ``SimSettings.touch``).
    """

    model: mujoco.MjModel
    joints: tuple[str, ...]
    qpos_adr: np.ndarray
    dof_adr: np.ndarray
    object_body: int
    object_qpos: int
    object_dof: int
    contact_bodies: tuple[int, ...]
    gravity: np.ndarray
    mu_tangential: float
    mu_torsional: float
    base_rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    followers: tuple[tuple[int, int, float, float], ...] = ()
    touch_adr: tuple[int, ...] = ()


def adapt_urdf(xml: str, urdf_dir: Path | None = None) -> str:
    """
    Rewrite the URDF as MuJoCo should load it.

    No joint friction or damping, no visuals, collision meshes at absolute paths
    (:func:`grasp_torque_opt.sim.robot.resolve_meshes`, relative ones in ``urdf_dir``),
    and a ``<mujoco><compiler .../></mujoco>`` extension (see the module docstring).

    Raises:
        InputError: the document is not XML with a ``robot`` root (field ``hand.urdf``).
    """
    try:
        root = ET.fromstring(xml)
    except ET.ParseError as e:
        raise InputError('hand.urdf', f'is not valid XML: {e}') from e
    if root.tag != 'robot':
        raise InputError('hand.urdf', f'root element must be <robot>, got <{root.tag}>')
    for link in root.iter('link'):
        for visual in link.findall('visual'):
            link.remove(visual)
    resolve_meshes(root, urdf_dir)
    for joint in root.iter('joint'):
        # The hand's coupling (mimic tags resolved, hand.coupling) becomes joint equalities
        # (sim/robot.py); MuJoCo's own mimic import would add another, or warn and ignore.
        for mimic in joint.findall('mimic'):
            joint.remove(mimic)
    for dynamics in root.iter('dynamics'):
        dynamics.set('friction', '0')
        dynamics.set('damping', '0')
    for old in root.findall('mujoco'):
        root.remove(old)
    ext = ET.SubElement(root, 'mujoco')
    ET.SubElement(ext, 'compiler', balanceinertia='true', fusestatic='false',
                  discardvisual='true', angle='radian', strippath='false')
    return ET.tostring(root, encoding='unicode')


def rpy_quaternion(rpy: np.ndarray) -> np.ndarray:
    """Quaternion [w, x, y, z] of roll-pitch-yaw about fixed x, y, z (URDF's convention)."""
    quat = np.zeros(4)
    mujoco.mju_euler2Quat(quat, np.asarray(rpy, dtype=float), 'XYZ')
    return quat


def _add_object(spec: mujoco.MjSpec, obj: ObjectSpec, mass: float, friction: list[float],
                timeconst: float, base: tuple[np.ndarray, np.ndarray]) -> None:
    R, t = base  # the base frame's rotation and origin in MuJoCo's world
    quat, Rb = np.zeros(4), np.zeros(4)
    mujoco.mju_mat2Quat(Rb, np.ascontiguousarray(R).ravel())
    mujoco.mju_mulQuat(quat, Rb, rpy_quaternion(obj.rpy))
    body = spec.worldbody.add_body(name=OBJECT_BODY, pos=list(R @ obj.position + t),
                                   quat=list(quat))
    body.add_freejoint(name=f'{OBJECT_BODY}_free')
    if obj.shape == 'sphere':
        kind, size = mujoco.mjtGeom.mjGEOM_SPHERE, [obj.size[0], 0.0, 0.0]
    elif obj.shape == 'box':
        kind, size = mujoco.mjtGeom.mjGEOM_BOX, list(np.asarray(obj.size) / 2)
    else:
        kind, size = mujoco.mjtGeom.mjGEOM_CYLINDER, [obj.size[0], obj.size[1] / 2, 0.0]
    # Uniform density: the centre of mass is the shape's centre, the object's position.
    body.add_geom(name=f'{OBJECT_BODY}_geom', type=kind, size=size, mass=mass,
                  friction=friction, condim=4, solref=[timeconst, 1.0],
                  contype=_OBJECT_BITS[0], conaffinity=_OBJECT_BITS[1],
                  rgba=OBJECT_RGBA)


def build_model(scenario: Scenario, settings: SimSettings = SimSettings(),
                urdf_xml: str | None = None, setup: GraspSetup | None = None) -> SimModel:
    """
    Compile the scenario's hand and object into a MuJoCo model.

    Args:
        scenario: a validated scenario with ``object`` and ``gravity``.
        settings: simulation settings (friction and mass overrides included).
        urdf_xml: a URDF document to use instead of the scenario's ``hand.urdf``.
        setup: the scenario bound to its hand (made here if None): which joints move,
            their coupling, and where ``hand.base_link`` is.

    Returns:
        The model, with the object at its pose, the actuators at 0, their followers at
        their grasp positions and every other joint welded at its grasp position.
        MuJoCo's world is the URDF's root; the object and gravity are placed there from
        ``hand.base_link``'s frame.

    Raises:
        InputError: naming the field: no object or gravity in the scenario, a
            URDF MuJoCo cannot load, a joint or contact link not in the model, a
            contact link without collision geometry.
    """
    if scenario.object is None:
        raise InputError('object', "the simulation needs the scenario's object "
                         '(shape, size, mass)')
    if scenario.gravity is None:
        raise InputError('gravity', "the simulation needs the scenario's gravity")
    spec, urdf_xml = _hand_spec(scenario, urdf_xml)
    if setup is None:
        # The simulated object may sit where the scenario's contacts are not (an offset
        # on purpose, --object-offset): the model is built from the hand and the object,
        # not from the contacts, so their warning says nothing here.
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', GeometryWarning)
            setup = GraspSetup.from_scenario(scenario, urdf_xml)
    coupled = weld_and_couple(spec, setup.hand, setup.q)
    base = base_placement(setup)
    mu1 = scenario.friction.mu1 if settings.mu_tangential is None else settings.mu_tangential
    mu2 = scenario.friction.mu2 if settings.mu_torsional is None else settings.mu_torsional
    mass = scenario.object.mass if settings.mass is None else settings.mass
    friction = [mu1, mu2, 0.0]
    _set_physics(spec, settings, base[0] @ scenario.gravity, friction)
    _add_object(spec, scenario.object, mass, friction, settings.contact_timeconst, base)
    try:
        model = spec.compile()
    except (ValueError, RuntimeError) as e:
        raise InputError('hand.urdf', f'MuJoCo cannot compile it: '
                         f'{str(e).strip().splitlines()[0]}') from e

    names, bodies = _checked_bodies(model, setup)
    touch = ()
    if settings.touch:
        model, touch = touch_sensors(spec, model, bodies)
    joints = setup.hand.joints
    free = model.joint(f'{OBJECT_BODY}_free')
    hand_dofs = [model.jnt_dofadr[j] for j in range(model.njnt) if model.joint(j).name in names]
    model.dof_damping[hand_dofs] = settings.joint_damping
    return SimModel(
        model=model, joints=tuple(joints),
        qpos_adr=np.array([model.joint(n).qposadr[0] for n in joints]),
        dof_adr=np.array([model.joint(n).dofadr[0] for n in joints]),
        object_body=model.body(OBJECT_BODY).id, object_qpos=int(free.qposadr[0]),
        object_dof=int(free.dofadr[0]), contact_bodies=tuple(bodies),
        gravity=np.array(scenario.gravity, dtype=float), mu_tangential=mu1, mu_torsional=mu2,
        base_rotation=base[0],
        followers=tuple((int(model.joint(m.joint).qposadr[0]),
                         int(model.joint(m.target).qposadr[0]), m.multiplier, m.offset)
                        for m in coupled),
        touch_adr=touch)


#: How far a touch sensor's site reaches beyond its link's collision shapes [m].
TOUCH_MARGIN = 0.002


def touch_sensors(spec: mujoco.MjSpec, model: mujoco.MjModel, bodies: list[int]
                  ) -> tuple[mujoco.MjModel, tuple[int, ...]]:
    """
    Put a touch sensor on each contact link, and compile again.

    MuJoCo's touch sensor sums the normal force of the contacts whose point lies inside
    its site and that involve its body: here a sphere around the link's collision shapes
    (their bounding spheres, ``TOUCH_MARGIN`` beyond), so every contact of the link
    counts, as a fingertip's tactile pad reads the whole tip.

    Returns:
        The model with the sensors, and per contact its sensor's ``sensordata`` address.
    """
    names = {}
    for body in dict.fromkeys(bodies):
        geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] == body]
        pos = model.geom_pos[geoms]
        centre = pos.mean(axis=0)
        radius = max(float(np.linalg.norm(p - centre)) + model.geom_rbound[g]
                     for g, p in zip(geoms, pos)) + TOUCH_MARGIN
        name = model.body(body).name
        spec.body(name).add_site(name=f'{name}_touch', pos=list(centre),
                                 size=[radius, 0.0, 0.0], type=mujoco.mjtGeom.mjGEOM_SPHERE,
                                 group=5)
        spec.add_sensor(name=f'{name}_touch', type=mujoco.mjtSensor.mjSENS_TOUCH,
                        objtype=mujoco.mjtObj.mjOBJ_SITE, objname=f'{name}_touch')
        names[body] = f'{name}_touch'
    model = spec.compile()
    return model, tuple(int(model.sensor_adr[model.sensor(names[b]).id]) for b in bodies)


def _hand_spec(scenario: Scenario, urdf_xml: str | None) -> tuple[mujoco.MjSpec, str]:
    """Return the hand's MuJoCo spec from its adapted URDF, and the URDF read."""
    urdf_dir = None
    if urdf_xml is None:
        path = resolve_urdf(scenario.urdf, scenario.base_dir)
        urdf_xml, urdf_dir = path.read_text(), path.parent
    try:
        spec = mujoco.MjSpec.from_string(adapt_urdf(urdf_xml, urdf_dir))
    except (ValueError, RuntimeError) as e:
        raise InputError('hand.urdf', f'MuJoCo cannot load it: '
                         f'{str(e).strip().splitlines()[0]}') from e
    return spec, urdf_xml


def _set_physics(spec: mujoco.MjSpec, settings: SimSettings, gravity: np.ndarray,
                 friction: list[float]) -> None:
    """Set the options (gravity in MuJoCo's world [m/s^2]) and the hand's contact geoms."""
    spec.option.timestep = settings.timestep
    spec.option.gravity = [float(x) for x in gravity]
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = settings.impratio
    spec.option.noslip_iterations = settings.noslip_iterations
    for geom in spec.geoms:
        geom.friction = friction
        geom.condim = 4
        geom.solref = [settings.contact_timeconst, 1.0]
        geom.contype, geom.conaffinity = _HAND_BITS


def _checked_bodies(model: mujoco.MjModel, setup: GraspSetup) -> tuple[list[str], list[int]]:
    """Return the model's 1-DoF joints and the contacts' bodies, each actuator and link checked."""
    names = [model.joint(j).name for j in range(model.njnt)
             if int(model.jnt_type[j]) in (int(mujoco.mjtJoint.mjJNT_HINGE),
                                           int(mujoco.mjtJoint.mjJNT_SLIDE))]
    for i, name in enumerate(setup.hand.joints):
        if name not in names:
            raise InputError(f'hand.joints[{i}]', f"'{name}' is not a 1-DoF joint of the "
                             'MuJoCo model')
    bodies = []
    for i, contact in enumerate(setup.contacts):  # found from geometry where not written
        field = f'grasp.contacts[{i}].link'
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, contact.link)
        if body < 0:
            raise InputError(field, f"'{contact.link}' is not a link of the MuJoCo model "
                             '(the simulation needs contacts on URDF links)')
        if model.body_geomnum[body] == 0:
            raise InputError(field, f"link '{contact.link}' has no collision geometry to "
                             'touch the object with')
        bodies.append(body)
    return names, bodies


def base_placement(setup: GraspSetup) -> tuple[np.ndarray, np.ndarray]:
    """Rotation and origin of the grasp's base frame in the URDF root's, at the grasp."""
    hand = setup.hand
    if hand.base_link is None:
        return np.eye(3), np.zeros(3)
    data = hand.model.createData()
    pin.framesForwardKinematics(hand.model, data, setup.q)
    oMb = data.oMf[hand.model.getFrameId(hand.base_link)]
    return oMb.rotation.copy(), oMb.translation.copy()
