# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The simulated fingertips' touch sensors (``SimSettings.touch``), against MuJoCo's contacts.

Real MuJoCo: the bundled Allegro grasp held by its certified torques plus g(q), the ball
pinned, then released. Each tip's touch sensor is compared with the normal force of the
contact solver's own forces at that tip (``mj_contactForce``, summed over the tip's
contacts and projected on their normal: :meth:`HandSim.readings`). A finger pulled off
the ball reads zero, and the node's tactile report (ROS-free) names it lost; without
``touch`` the model has no sensor.
"""

import re

from conftest import ALLEGRO, CONFIG
from cycle_inputs import fresh, joint_state
from grasp_torque_opt.control.inputs.joint_states import JointStateReading
from grasp_torque_opt.control.inputs.tactile import TactileArrayReading
from grasp_torque_opt.core.scenario import load_scenario
from grasp_torque_opt.sim.hold import certified_torques
from grasp_torque_opt.sim.model import build_model, SimSettings
from grasp_torque_opt.sim.simulator import HandSim
import numpy as np
import pytest
from test_sim_driver import run, summary_of
import yaml

SCENARIO = load_scenario(ALLEGRO)


@pytest.fixture(scope='module')
def grasp():
    return certified_torques(SCENARIO)


def holding(grasp, touch=True):
    setup, _, sol, _ = grasp
    hand = setup.hand
    hsim = HandSim(build_model(SCENARIO, SimSettings(touch=touch), setup=setup),
                   setup.q[hand.idx_q])
    q = setup.q.copy()

    def command(extra=0.0):
        q[hand.idx_q] = hsim.q
        return sol.tau + hand.gravity_torques(hand.complete(q), SCENARIO.gravity) + extra
    return hsim, command


def contact_normals(hsim):
    readings, _ = hsim.readings()
    return np.array([r.force @ r.normal if r.touching else 0.0 for r in readings])


def test_the_touch_sensors_read_the_contact_solvers_normal_forces(grasp):
    hsim, command = holding(grasp)
    assert len(hsim.sim.touch_adr) == 4
    compared = 0
    for k in range(600):
        hsim.command = command()
        hsim.step()
        if k == 300:
            hsim.release()
        if k % 20 == 19:
            measured = contact_normals(hsim)
            assert np.all(measured > 0.3), (k, measured)
            np.testing.assert_allclose(hsim.touch(), measured, rtol=1e-9, atol=1e-9)
            compared += 1
    assert compared == 30
    drift, _ = hsim.motion()
    assert drift < 1e-3
    # The certified normal forces, read back within 2% after the release.
    np.testing.assert_allclose(hsim.touch(), grasp[2].wrenches[:, 2], rtol=0.02)


def test_a_finger_pulled_off_reads_zero_and_is_reported_lost(grasp, allegro):
    hsim, command = holding(grasp)
    index = [list(hsim.sim.joints).index(f'joint_{j}.0') for j in (1, 2, 3)]
    open_index = np.zeros(len(hsim.sim.joints))
    open_index[index] = -0.1  # N m: the index finger extends, away from the pinned ball
    for _ in range(200):
        hsim.command = command()
        hsim.step()
    before = hsim.touch()
    for _ in range(300):
        hsim.command = command(open_index)
        hsim.step()
    after = hsim.touch()
    # (The other tips chatter on the pinned ball, their torques no longer balanced: their
    # readings still agree with the solver's.)
    assert before[0] > 0.3 and after[0] == 0.0 and not hsim.readings()[0][0].touching
    np.testing.assert_allclose(after, contact_normals(hsim), atol=1e-9)
    # The node's report (ROS-free) on the sensors as the driver publishes them: lost is
    # every tip below loss_ratio (0.3) of its planned normal force, the index among them.
    links = tuple(c.link for c in grasp[0].contacts)
    ctrl = fresh(allegro, tactile_source='array', tactile_links=links)
    ctrl.take('joint_states', JointStateReading(*joint_state(allegro)), 1.0)
    ctrl.take('tactile', TactileArrayReading(after), 1.0)
    assert ctrl.cycle(1.0).kind == 'solution'
    planned = ctrl.tactile.planned
    expected = tuple(i for i in range(4) if after[i] < 0.3 * planned[i])
    assert 0 in ctrl.tactile.lost and ctrl.tactile.lost == expected, (after, planned)
    assert ctrl.tactile.usage[0] == np.inf
    ctrl.take('tactile', TactileArrayReading(before), 1.01)
    ctrl.cycle(1.01)
    assert ctrl.tactile.lost == ()


def test_without_touch_there_is_no_sensor(grasp):
    hsim, _ = holding(grasp, touch=False)
    assert hsim.model.nsensor == 0 and hsim.touch().size == 0


def required_params(tmp_path):
    """Write the bundled node's params with tactile required: it commands only on tactile."""
    doc = yaml.safe_load((CONFIG / 'allegro_right_node.yaml').read_text())
    doc['/**']['ros__parameters']['tactile'] = {
        'source': 'array', 'links': [c.link for c in SCENARIO.contacts], 'required': True,
        'timeout': 0.2}
    path = tmp_path / 'tactile_node.yaml'
    path.write_text(yaml.safe_dump(doc))
    return str(path)


def test_the_node_commands_on_the_simulated_hands_tactile_over_ros(tmp_path):
    """
    Run grasp-torque-sim --tactile with the node over ROS, tactile.required on the node.

    The node commands only while every tip's reading arrives fresh and accepted: the
    ball is held; without --tactile the same node gets none and never commands.
    """
    params = required_params(tmp_path)
    done = run('--with-node', '--params', params, '--tactile', '--duration', '1',
               '--no-picture')
    assert done.returncode == 0, done.stdout + done.stderr
    assert ('tactile.source array, tactile.links [link_3.0_tip,link_7.0_tip,link_11.0_tip,'
            'link_15.0_tip]') in done.stdout
    summary = summary_of(done)
    assert summary.startswith('summary: held: drift '), summary
    assert int(re.search(r'; (\d+) commands', summary).group(1)) > 100
    done = run('--with-node', '--params', params, '--duration', '1', '--no-picture',
               '--wait', '5')
    assert done.returncode == 1 and 'no effort command' in done.stderr, done.stdout
