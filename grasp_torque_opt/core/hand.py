# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The hand: a Pinocchio model loaded from URDF, its actuated joints and torque limits.

A URDF is read within bounds (docs/design.md section 4.1): a regular file of at most
:data:`MAX_URDF_BYTES`, UTF-8, at most :data:`MAX_URDF_ELEMENTS` ``<joint>`` and
``<link>`` elements, a model of at most :data:`MAX_MODEL_DOF` degrees of freedom:
Pinocchio's workspace grows as nv^3 on a chain (23 MB at 64, 142 MB at 128, 1.1 GB at
256 here), and a 500-joint URDF of 170 KB took over 4 GB.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field
from functools import cached_property
from importlib import metadata
import os
from pathlib import Path
import re
import tempfile
from xml.etree import ElementTree

from grasp_torque_opt.core.coupling import Coupling, COUPLING_TOLERANCE, Mimic, urdf_mimics
from grasp_torque_opt.core.exceptions import (
    cut,
    FrameNotFound,
    InputError,
    JointNotFound,
    PATH_LENGTH,
)
from grasp_torque_opt.core.resources import decode_utf8, read_bounded
import numpy as np
import pinocchio as pin

ERD_PREFIX = 'example-robot-data:'
#: Largest torque limit accepted at all [N m], also when a limit above the URDF's effort
#: limit is allowed: a bound on what any command can be (1e300 was accepted once).
MAX_TORQUE_LIMIT = 1e4
#: Largest URDF read [bytes] (example-robot-data's largest, tiago_dual, is 211 KB).
MAX_URDF_BYTES = 2 * 1024 * 1024
#: Most ``<joint`` and ``<link`` elements each (transmissions name joints too), counted
#: before Pinocchio parses the document (a 256-joint chain took 0.8 s to build here).
MAX_URDF_ELEMENTS = 512
#: Most actuated joints of a hand (its actuators: coupled joints count once).
MAX_MODEL_DOF = 64
#: Most degrees of freedom (nv) of the whole model (a hand inside a robot): its workspace
#: is allocated next.
MAX_ROBOT_DOF = 128
#: Most one-DoF joints a model may have for ``hand.joints`` to be left out: a model with
#: more is a robot around a hand, whose legs and arms must not become actuators.
MAX_IMPLICIT_JOINTS = 30
_ELEMENT = {tag: re.compile(rf'<{tag}[\s/>]') for tag in ('joint', 'link')}


@contextlib.contextmanager
def quiet_fd2():
    """
    Keep what C++ writes on file descriptor 2 off the terminal while the block runs.

    urdfdom prints its own "Error: ... at line N in joint.cpp" lines there before
    Pinocchio raises; the caller's one-line error (naming the field) says it instead.
    """
    sys_err = os.dup(2)
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 2)
        try:
            yield
        finally:
            os.dup2(sys_err, 2)
            os.close(sys_err)


def parse_urdf(xml: str) -> pin.Model:
    """Build the Pinocchio model of a URDF document, urdfdom's own lines kept quiet."""
    with quiet_fd2():
        return pin.buildModelFromXML(xml)


def example_robot_data_dir() -> Path:
    """
    Folder ``robots/`` of example-robot-data.

    Looked up in this order: the pip distribution ``example-robot-data`` (its
    cmeel prefix), then ``share/example-robot-data/robots`` under each entry
    of ``AMENT_PREFIX_PATH`` (a ROS installation).

    Raises:
        InputError: example-robot-data is not installed.
    """
    candidates = []
    try:
        dist = metadata.distribution('example-robot-data')
        candidates.append(Path(dist.locate_file('cmeel.prefix/share/example-robot-data/robots')))
    except metadata.PackageNotFoundError:
        pass
    for prefix in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep):
        if prefix:
            candidates.append(Path(prefix) / 'share' / 'example-robot-data' / 'robots')
    for c in candidates:
        if c.is_dir():
            return c
    raise InputError('hand.urdf', 'example-robot-data is not installed '
                     '(pip install example-robot-data, or source a ROS installation that has it)')


def resolve_urdf(spec: str, base_dir: Path) -> Path:
    """
    Resolve a URDF reference of a scenario to a file.

    Args:
        spec: ``example-robot-data:<path under robots/>``, an absolute path, or a
            path relative to ``base_dir``.
        base_dir: folder of the scenario file.

    Raises:
        InputError: the file does not exist (field ``hand.urdf``); an existing
            directory or device is refused by :meth:`Hand.from_urdf`, saying so.
    """
    if spec.startswith(ERD_PREFIX):
        path = example_robot_data_dir() / spec[len(ERD_PREFIX):]
    else:
        path = Path(spec).expanduser()
        if not path.is_absolute():
            path = base_dir / path
    if not os.path.exists(path):  # False on any OSError, e.g. a name too long
        raise InputError('hand.urdf', f'file not found: {cut(path, PATH_LENGTH)}')
    return path


def bounded_urdf(xml: str, field_name: str) -> str:
    """
    Return ``xml`` if within :data:`MAX_URDF_BYTES` and :data:`MAX_URDF_ELEMENTS`.

    Raises:
        InputError: naming ``field_name``.
    """
    if len(xml) > MAX_URDF_BYTES:
        raise InputError(field_name, f'the URDF is larger than {MAX_URDF_BYTES} bytes')
    for tag, pattern in _ELEMENT.items():
        n = len(pattern.findall(xml))
        if n > MAX_URDF_ELEMENTS:
            raise InputError(field_name, f'the URDF has {n} <{tag}> elements, more than '
                             f'{MAX_URDF_ELEMENTS}')
    return xml


def check_inertials(xml: str, field_name: str) -> None:
    """
    Refuse a URDF whose links' masses or inertias the model cannot use, naming the link.

    Read before Pinocchio parses the document: urdfdom dropped a NaN inertia with a line
    on the terminal for each (69 for one URDF), so g(q) was certified with a wrong model;
    a negative mass started a node that never commanded; a malformed document gave
    urdfdom's three lines. Each value must be a number, finite; a mass and the inertia's
    diagonal not negative (0: a massless link).

    Args:
        xml: the URDF document (within :func:`bounded_urdf`'s bounds).
        field_name: the field named in the message (``hand.urdf``, ``robot_description``).

    Raises:
        InputError: one line: the document does not parse as XML, or the link and value.
    """
    try:
        root = ElementTree.fromstring(xml)
    except ElementTree.ParseError as e:
        raise InputError(field_name, f'cannot parse the URDF: {e}') from e
    for link in root.iter('link'):
        inertial = link.find('inertial')
        if inertial is None:
            continue
        name = cut(link.get('name', '?'))
        values = [('mass', (inertial.find('mass'), ('value',)), True),
                  ('inertia', (inertial.find('inertia'), ('ixx', 'iyy', 'izz')), True),
                  ('inertia', (inertial.find('inertia'), ('ixy', 'ixz', 'iyz')), False)]
        for tag, (element, keys), signed in values:
            for key in keys if element is not None else ():
                text = element.get(key, '0')
                try:
                    value = float(text)
                except ValueError:
                    value = float('nan')
                if not np.isfinite(value) or (signed and value < 0.0):
                    raise InputError(field_name, f"link '{name}': {tag} {key}="
                                     f"'{cut(text, 40)}' must be a finite number"
                                     + (' >= 0' if signed else ''))


def frame_names(model: pin.Model) -> list[str]:
    """
    Return the model's frame names, the relevant first: links, then the other frames.

    A contact sits on a link (a BODY frame); the joint frames (on the Allegro, as many
    as its links) come after them, each group sorted by name.
    """
    def natural(name: str) -> list:
        return [int(t) if t.isdigit() else t for t in re.split(r'(\d+)', name)]

    bodies = sorted({f.name for f in model.frames if f.type == pin.FrameType.BODY}, key=natural)
    others = sorted({f.name for f in model.frames} - set(bodies), key=natural)
    return bodies + others


@dataclass(frozen=True)
class Hand:
    """
    A hand model with its actuated joints in command order.

    Attributes:
        model: Pinocchio model; its world frame is the root frame.
        joints: actuated joint names in command order (m of them): with coupled
            joints, the actuators (docs/design.md section 1).
        data: Pinocchio workspace of ``model``.
        idx_q: index of each actuated joint in q, shape (m,).
        idx_v: index of each actuated joint in v (columns of the Jacobians), shape (m,).
        torque_limits: |tau_i| <= torque_limits[i] [N m], shape (m,).
        coupling: the coupled joints (URDF mimic tags and ``hand.coupling``).
        velocity_map: C, shape (nv, m), dq = C dtheta, or None when no coupled joint
            follows an actuator (then C selects the columns ``idx_v``).
        base_link: the frame the grasp is written in (``hand.base_link``), or None for
            the model's root link.
    """

    model: pin.Model
    joints: list[str]
    idx_q: np.ndarray
    idx_v: np.ndarray
    torque_limits: np.ndarray
    coupling: Coupling = field(default_factory=Coupling)
    velocity_map: np.ndarray | None = None
    base_link: str | None = None
    data: pin.Data = field(init=False, repr=False, compare=False)
    _frame_ids: dict[str, int] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        # Kinematics workspace, allocated once; a Hand is not shared across threads.
        object.__setattr__(self, 'data', self.model.createData())
        object.__setattr__(self, '_frame_ids', {})

    def frame_index(self, name: str, field_name: str) -> int:
        """
        Index of a model frame by name, looked up once per name.

        Raises:
            FrameNotFound: naming ``field_name`` and listing close matches.
        """
        fid = self._frame_ids.get(name)
        if fid is None:
            if not self.model.existFrame(name):
                raise FrameNotFound(field_name, name, frame_names(self.model))
            fid = self._frame_ids[name] = self.model.getFrameId(name)
        return fid

    @property
    def m(self) -> int:
        """Return the number of actuated joints."""
        return len(self.joints)

    @cached_property
    def base_frame(self) -> str:
        """
        Return the name of the base frame: ``base_link``, else the root link.

        Looked up once: the node stamps every command with it.
        """
        return self.base_link if self.base_link is not None else self.root_frame

    @cached_property
    def root_frame(self) -> str:
        """Return the name of the model's root link (Pinocchio's world, MuJoCo's)."""
        return next(f.name for f in self.model.frames
                    if f.type == pin.FrameType.BODY and f.parentJoint == 0)

    def actuator_torques(self, tau: np.ndarray) -> np.ndarray:
        """Return u = C^T tau, shape (m,), from joint torques tau of shape (nv,) [N m]."""
        if self.velocity_map is None:
            return np.asarray(tau)[self.idx_v].copy()
        return self.velocity_map.T @ tau

    def gravity_torques(self, q: np.ndarray, gravity: np.ndarray) -> np.ndarray:
        """
        Return the actuators' gravity torques C^T g(q) [N m], shape (m,).

        Args:
            q: full configuration.
            gravity: gravity in the base frame (``base_link``'s axes if set) [m/s^2].
        """
        g = np.asarray(gravity, dtype=float)
        if self.base_link is not None:
            pin.framesForwardKinematics(self.model, self.data, q)
            g = self.data.oMf[self.frame_index(self.base_link, 'hand.base_link')].rotation @ g
        self.model.gravity.linear = g
        return self.actuator_torques(pin.computeGeneralizedGravity(self.model, self.data, q))

    def complete(self, q: np.ndarray) -> np.ndarray:
        """Set the coupled joints' positions in ``q`` from their targets (in place)."""
        return self.coupling.apply(self.model, q)

    @staticmethod
    def one_dof_joints(model: pin.Model) -> list[str]:
        """Names of the model's one-degree-of-freedom joints, in model order."""
        return [model.names[j] for j in range(1, model.njoints)
                if model.joints[j].nq == 1 and model.joints[j].nv == 1]

    @property
    def effort_limits(self) -> np.ndarray:
        """Return the URDF's effort limit of each actuated joint [N m], inf where it gives none."""
        e = np.asarray(self.model.effortLimit, dtype=float)[self.idx_v]
        return np.where(np.isfinite(e) & (e > 0.0), e, np.inf)

    @staticmethod
    def check_limits(limits: np.ndarray, joints: list[str], bounds: np.ndarray,
                     field: str, override: str) -> None:
        """
        Each limit finite, > 0 and at most its bound (the URDF's effort limit).

        Raises:
            InputError: naming ``field`` and the first joint over its bound, and the
                setting ``override`` that allows more.
        """
        if not np.all(np.isfinite(limits) & (limits > 0.0)):
            raise InputError(field, 'must be finite and > 0')
        over = np.flatnonzero(limits > bounds)
        if over.size:
            i = int(over[0])
            what = ('the URDF effort limit' if bounds[i] < MAX_TORQUE_LIMIT
                    else 'the largest limit accepted')
            raise InputError(field, f"{limits[i]:g} N m for joint '{joints[i]}' exceeds "
                             f'{what} ({bounds[i]:g} N m)' + (
                                 f'; set {override}: true to allow it'
                                 if bounds[i] < MAX_TORQUE_LIMIT else ''))

    @classmethod
    def from_model(cls, model: pin.Model, joints: list[str] | None = None,
                   torque_limits: float | list[float] | np.ndarray | None = None,
                   above_urdf: bool = False, mimics: list[Mimic] | None = None,
                   base_link: str | None = None) -> Hand:
        """
        Bind actuated joints and limits to a model.

        Args:
            model: the Pinocchio model.
            joints: actuated joints in command order; None for every 1-DoF joint that
                follows no other (below ``base_link`` if given).
            torque_limits: scalar or per-joint bound [N m]; None for the URDF
                effort limits.
            above_urdf: allow limits above the URDF's effort limits (up to
                :data:`MAX_TORQUE_LIMIT`).
            mimics: coupled joints (the URDF's, then the scenario's over them).
            base_link: the frame of the grasp (``hand.base_link``), or None.

        Raises:
            JointNotFound: a joint is not a 1-DoF joint of the model (``hand.joints[i]``).
            InputError: a limit is missing, not positive, or above the joint's URDF
                effort limit without ``above_urdf`` (``hand.torque_limits``); a coupled
                joint listed as actuated; an actuated joint not below ``base_link``; a
                robot-sized model without ``hand.joints``.
        """
        if model.nv > MAX_ROBOT_DOF:
            raise InputError('hand.urdf', f'the model has {model.nv} degrees of freedom, more '
                             f'than {MAX_ROBOT_DOF}')
        coupling = Coupling.resolve(model, mimics or [])
        joints = cls._actuated(model, joints, coupling, base_link)
        ids = [model.getJointId(n) for n in joints]
        idx_q = np.array([model.joints[j].idx_q for j in ids], dtype=int)
        idx_v = np.array([model.joints[j].idx_v for j in ids], dtype=int)
        limits = _torque_limits(model, joints, idx_v, torque_limits, above_urdf)
        C = coupling.velocity_map(model, idx_v)
        selection = np.count_nonzero(C) == len(joints)
        return cls(model=model, joints=list(joints), idx_q=idx_q, idx_v=idx_v,
                   torque_limits=np.array(limits, dtype=float), coupling=coupling,
                   velocity_map=None if selection else C, base_link=base_link)

    @classmethod
    def _actuated(cls, model: pin.Model, joints: list[str] | None, coupling: Coupling,
                  base_link: str | None) -> list[str]:
        """Return the actuated joints, checked (``from_model``'s ``joints``, or the default)."""
        followers = coupling.followers
        available = cls.one_dof_joints(model)
        base_joint = None
        if base_link is not None:
            if not model.existFrame(base_link):
                raise FrameNotFound('hand.base_link', base_link, frame_names(model))
            base_joint = model.frames[model.getFrameId(base_link)].parentJoint
        if joints is None:
            joints = [n for n in available if n not in followers and (
                base_joint is None or cls._below(model, n, base_joint))]
            if len(joints) > MAX_IMPLICIT_JOINTS:
                raise InputError('hand.joints', f'required: the model has {len(joints)} '
                                 f'one-DoF joints, more than a hand ({MAX_IMPLICIT_JOINTS}); '
                                 "list the hand's joints (or set hand.base_link to the hand's "
                                 'palm: then the joints below it are the default)')
        if len(joints) > MAX_MODEL_DOF:
            raise InputError('hand.joints', f'{len(joints)} actuated joints, more than '
                             f'{MAX_MODEL_DOF}')
        for i, name in enumerate(joints):
            if name not in available:
                raise JointNotFound(f'hand.joints[{i}]', name, available)
            if name in followers:
                m = followers[name]
                raise InputError(f'hand.joints[{i}]', f"'{name}' follows '{m.target}' "
                                 f'(coupled in {m.source}): list its actuator '
                                 f"'{coupling.root(name)}' only")
        if base_joint is not None:
            for i, name in enumerate(joints):
                if not cls._below(model, name, base_joint):
                    raise InputError(f'hand.joints[{i}]', f"joint '{name}' does not move "
                                     f"below hand.base_link '{base_link}'")
        return joints

    @staticmethod
    def _below(model: pin.Model, name: str, base_joint: int) -> bool:
        """Tell whether joint ``name`` moves its child links relative to ``base_joint``'s."""
        j = model.getJointId(name)
        return j != base_joint and base_joint in list(model.supports[j])

    @classmethod
    def from_urdf(cls, path: str | Path, joints: list[str] | None = None,
                  torque_limits: float | list[float] | np.ndarray | None = None,
                  above_urdf: bool = False, mimics: list[Mimic] | None = None,
                  base_link: str | None = None) -> Hand:
        """
        Load a hand from a URDF file, within the module's bounds.

        The base is fixed; meshes are not needed. The URDF's mimic tags couple joints,
        ``mimics`` (the scenario's ``hand.coupling``) over them.
        """
        path = Path(path)
        xml = decode_utf8(read_bounded(path, 'hand.urdf', MAX_URDF_BYTES), path, 'hand.urdf')
        check_inertials(bounded_urdf(xml, 'hand.urdf'), 'hand.urdf')
        try:
            model = parse_urdf(xml)
        except (RuntimeError, ValueError) as e:
            raise InputError('hand.urdf',
                             f'cannot parse {cut(path, PATH_LENGTH)}: {cut(e, 400)}') from e
        return cls.from_model(model, joints, torque_limits, above_urdf,
                              urdf_mimics(xml) + list(mimics or []), base_link)

    @classmethod
    def from_urdf_string(cls, xml: str, joints: list[str] | None = None,
                         torque_limits: float | list[float] | np.ndarray | None = None,
                         above_urdf: bool = False, mimics: list[Mimic] | None = None,
                         base_link: str | None = None) -> Hand:
        """
        Load a hand from a URDF document, within the module's bounds.

        The document may be, e.g., the ``robot_description`` parameter.
        """
        check_inertials(bounded_urdf(xml, 'robot_description'), 'robot_description')
        try:
            model = parse_urdf(xml)
        except (RuntimeError, ValueError) as e:
            raise InputError('robot_description', f'cannot parse the URDF: {cut(e, 400)}') from e
        return cls.from_model(model, joints, torque_limits, above_urdf,
                              urdf_mimics(xml) + list(mimics or []), base_link)

    def configuration(self, positions: dict[str, float],
                      field: str = 'grasp.joint_positions') -> np.ndarray:
        """
        Full configuration q from joint positions by name; others stay at 0.

        Coupled joints take the positions their coupling gives; one given a position
        that contradicts it is an error.

        Raises:
            JointNotFound: a name is not a 1-DoF joint of the model.
            InputError: a coupled joint's position contradicts its coupling.
        """
        q = pin.neutral(self.model)
        available = self.one_dof_joints(self.model)
        for name, value in positions.items():
            if name not in available:
                raise JointNotFound(f'{field}.{name}', name, available)
            q[self.model.joints[self.model.getJointId(name)].idx_q] = value
        self.complete(q)
        for m in self.coupling.mimics:
            value = q[self.model.joints[self.model.getJointId(m.joint)].idx_q]
            if m.joint not in positions or abs(positions[m.joint] - value) <= COUPLING_TOLERANCE:
                continue
            raise InputError(f'{field}.{m.joint}', f'is {positions[m.joint]:.6g}, but '
                             f"'{m.joint}' = {m.multiplier:g} * '{m.target}' + {m.offset:g} "
                             f'= {value:.6g} (coupled in {m.source}); leave it out')
        return q


def _torque_limits(model: pin.Model, joints: list[str], idx_v: np.ndarray,
                   torque_limits: float | list[float] | np.ndarray | None,
                   above_urdf: bool) -> np.ndarray:
    """Return ``Hand.from_model``'s torque limits [N m], checked: given, or the URDF's efforts."""
    if torque_limits is None:
        limits = np.asarray(model.effortLimit, dtype=float)[idx_v]
        for name, lim in zip(joints, limits):
            if not (np.isfinite(lim) and lim > 0.0):
                raise InputError('hand.torque_limits',
                                 f"the URDF gives no effort limit for joint '{name}'; "
                                 'set hand.torque_limits')
        return limits
    limits = np.asarray(torque_limits, dtype=float)
    if limits.ndim > 1 or (limits.ndim == 1 and limits.size != len(joints)):
        raise InputError('hand.torque_limits',
                         f'must have {len(joints)} entries (one per joint), '
                         f'got {limits.size}')
    limits = np.broadcast_to(limits, (len(joints),))
    effort = np.asarray(model.effortLimit, dtype=float)[idx_v]
    bounds = np.full(len(joints), MAX_TORQUE_LIMIT)
    if not above_urdf:
        known = np.isfinite(effort) & (effort > 0.0)
        bounds[known] = np.minimum(effort[known], MAX_TORQUE_LIMIT)
    Hand.check_limits(limits, list(joints), bounds, 'hand.torque_limits',
                      'hand.torque_limits_above_urdf')
    return limits
