# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
A user's own URDF with other names, and the bundled scenario, through the name map.

The test writes a copy of example-robot-data's Allegro URDF whose joints and links
are renamed the way the vendor's ROS 2 stack names them (``joint_4.0`` becomes
``ah_joint10``, ``link_3.0_tip`` becomes ``ah_link03_tip``, ``palm_link`` becomes
``ah_palm``), and runs the node on it with the bundled Allegro scenario. Its torques
must be those of the original names, computed here from the core on the original URDF.
"""

import dataclasses
from pathlib import Path
import re

from conftest import ALLEGRO, ALLEGRO_URDF, scenario_doc
from cycle_inputs import joint_state
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.core.grasp_setup import GraspSetup
from grasp_torque_opt.core.hand import resolve_urdf
from grasp_torque_opt.methods.dispatch import solve
from grasp_torque_opt.ros.node import COMMAND_QOS, GraspTorqueNode
import numpy as np
import pinocchio as pin
import pytest
import rclpy
from rclpy.parameter import Parameter
from ros_harness import DOMAIN, Harness
from sensor_msgs.msg import JointState
import yaml


def renamed(name: str) -> str:
    """Rename an example-robot-data Allegro joint or link as the vendor's stack names it."""
    if name == 'palm_link':
        return 'ah_palm'
    m = re.fullmatch(r'(joint|link)_(\d+)\.0(_tip)?', name)
    if m is None:
        return name
    i = int(m.group(2))
    return f'ah_{m.group(1)}{i // 4}{i % 4}{m.group(3) or ""}'


def write_renamed_urdf(folder: Path) -> Path:
    """Write a copy of the Allegro URDF with every joint and link renamed; give its path."""
    text = resolve_urdf(ALLEGRO_URDF, Path('.')).read_text()
    out = re.sub(r'"((?:joint|link)_\d+\.0(?:_tip)?|palm_link)"',
                 lambda m: f'"{renamed(m.group(1))}"', text)
    assert 'joint_0.0' not in out and 'ah_joint00' in out and '"ah_palm"' in out
    path = folder / 'ah_right_hand.urdf'
    path.write_text(out)
    return path


#: What the bundled scenario names, mapped: its 16 joints and its 4 contact links.
NAME_MAP = ([f'joint_{i}.0={renamed(f"joint_{i}.0")}' for i in range(16)]
            + [f'link_{i}.0_tip={renamed(f"link_{i}.0_tip")}' for i in (3, 7, 11, 15)])


def original_command(allegro):
    """
    Compute the bundled grasp's command with gravity compensation, original names and order.

    From the core on example-robot-data's own URDF: g(q) from Pinocchio under the
    scenario's gravity, then the tau-QP with it as the offset.
    """
    model = pin.buildModelFromUrdf(str(resolve_urdf(ALLEGRO_URDF, Path('.'))))
    model.gravity.linear = np.array([9.81, 0.0, 0.0])  # the scenario's, palm down
    g = pin.computeGeneralizedGravity(model, model.createData(), allegro.q)[allegro.hand.idx_v]
    sol = solve(dataclasses.replace(GraspSetup.from_file(ALLEGRO), torque_offset=g))
    assert sol.optimal
    return dict(zip(allegro.hand.joints, sol.tau + g))


def test_a_renamed_urdf_commands_the_original_torques_in_its_own_names_and_order(
        allegro, tmp_path):
    urdf = write_renamed_urdf(tmp_path)
    # The command order in the URDF's names, thumb first (not the scenario's order).
    thumb_first = (12, 13, 14, 15, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11)
    order = [renamed(f'joint_{i}.0') for i in thumb_first]
    # gravity_timeout 0: the gravity sent below must not go stale while a loaded machine
    # runs this test (a stale input stops commands; that rule has its own tests).
    h = Harness(ALLEGRO, robot_description=str(urdf), name_map=NAME_MAP, joints=order,
                gravity_compensation=True, publish_stamped_command=True, gravity_timeout=0.0)
    try:
        stamped = []
        h.tester.create_subscription(JointState, 'grasp_torque_node/effort_commands_stamped',
                                     stamped.append, COMMAND_QOS)
        assert h.spin_until(lambda: h.node.count_subscribers(
            'grasp_torque_node/effort_commands_stamped') > 0, 5.0)
        assert list(h.node.get_parameter('joints').value) == order
        # The hand's joint states, in the URDF's names, shuffled.
        names, pos = joint_state(allegro)
        names = [renamed(n) for n in names]
        h.send_joint_state(names[::-1], pos[::-1])
        cmd = h.next_command()
        assert cmd is not None and cmd.shape == (16,)
        expected = original_command(allegro)
        original = {renamed(n): n for n in expected}
        np.testing.assert_allclose(cmd, [expected[original[j]] for j in order], atol=1e-9)
        # The base frame is the URDF's root link, renamed too.
        assert h.spin_until(lambda: stamped, 2.0)
        assert list(stamped[-1].name) == order and stamped[-1].header.frame_id == 'ah_palm'
        assert h.spin_until(lambda: h.diagnostics and any(
            k.startswith('contact0.ah_link03_tip') for k in h.diagnostics[-1]), 2.0)
        # Gravity in the renamed base frame is taken; the old name is no frame of this hand.
        h.send_gravity('palm_link', [9.81, 0.0, 0.0])
        assert h.spin_until(lambda: h.node.controller.counters.rejected.get('gravity') == 1, 2.0)
        h.send_gravity('ah_palm', [9.81, 0.0, 0.0])
        assert h.spin_until(lambda: h.node.controller.inputs.gravity is not None, 2.0)
        h.send_joint_state(names, pos)
        np.testing.assert_allclose(h.next_command(), cmd, atol=1e-9)
    finally:
        h.close()


def test_the_scenarios_own_name_map_and_the_parameter_over_it(allegro, tmp_path):
    """
    Map the joints in a scenario file (hand.name_map) and the links with the parameter.

    A scenario written for the renamed URDF maps its joints itself; the node's
    ``name_map`` maps the contact links on top of it. The torques are the original's.
    """
    urdf = write_renamed_urdf(tmp_path)
    doc = scenario_doc(ALLEGRO)
    doc['hand']['urdf'] = str(urdf)
    doc['hand']['name_map'] = {f'joint_{i}.0': renamed(f'joint_{i}.0') for i in range(16)}
    scenario = tmp_path / 'ah_scenario.yaml'
    scenario.write_text(yaml.safe_dump(doc))
    links = [e for e in NAME_MAP if e.startswith('link_')]
    h = Harness(scenario, name_map=links, gravity_compensation=True)
    try:
        names, pos = joint_state(allegro)
        h.send_joint_state([renamed(n) for n in names], pos)
        cmd = h.next_command()
        expected = original_command(allegro)
        joints = list(h.node.get_parameter('joints').value)
        assert joints == [renamed(n) for n in allegro.hand.joints]
        np.testing.assert_allclose(cmd, [expected[n] for n in allegro.hand.joints], atol=1e-9)
    finally:
        h.close()


@pytest.mark.parametrize('name_map,error', [
    # Without the map, the scenario's names are not the URDF's: said, with the way out.
    (None, r"^hand\.joints\[0\]: unknown joint 'joint_0\.0' \(did you mean .*\? "
           r'1-DoF joints: ah_joint00, .*'
     r'map them to this URDF.s names with the name_map parameter \(SCENARIO_NAME=URDF_NAME\) '
     r'or the scenario.s hand\.name_map$'),
    (['joint_0.0'], r"^name_map\[0\]: must be SCENARIO_NAME=URDF_NAME, got 'joint_0\.0'$"),
    (['joint_0.0=a=b'], r'^name_map\[0\]: must be SCENARIO_NAME=URDF_NAME'),
    (['joint_0.0=ah_joint00', 'joint_0.0=ah_joint01'],
     r"^name_map\[1\]: maps 'joint_0\.0' a second time$"),
    (['joint_0.0=ah_joint00', 'joint_1.0=ah_joint00'],
     r"^name_map\.joint_1\.0: maps to 'ah_joint00', as 'joint_0\.0' does: two names cannot "
     r'map to one$'),
    (NAME_MAP[:15] + ['joint_15.0=ah_joint00'] + NAME_MAP[16:],
     r"^name_map\.joint_15\.0: maps to 'ah_joint00'"),
    # Only the joints mapped: the contacts' links are not the URDF's.
    (NAME_MAP[:16], r"^grasp\.contacts\[0\]\.link: unknown frame 'link_3\.0_tip'"),
])
def test_a_missing_or_bad_name_map_is_refused_at_start_naming_it(tmp_path, name_map, error):
    urdf = write_renamed_urdf(tmp_path)
    ctx = rclpy.Context()
    rclpy.init(context=ctx, domain_id=DOMAIN)
    overrides = [Parameter('scenario', value=str(ALLEGRO)),
                 Parameter('robot_description', value=str(urdf))]
    if name_map is not None:
        overrides.append(Parameter('name_map', value=name_map))
    try:
        with pytest.raises(InputError, match=error):
            GraspTorqueNode(context=ctx, parameter_overrides=overrides)
    finally:
        rclpy.try_shutdown(context=ctx)
