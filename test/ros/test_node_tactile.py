# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
The tactile input over ROS (issue 32, item 5): real node, real topics.

The Allegro V5 Sense's 16-value std_msgs/Float32MultiArray mapped by ``tactile.links``,
and the per-link geometry_msgs/WrenchStamped form. A bad message (NaN, a wrong length,
an unknown or unmapped link, a pulling or oversized force, too many bytes) is rejected,
counted and named on /diagnostics, and never used: the tactile values stay the last good
ones and every command stays the certified one of its joint state. A stale reading is
said (tactile not required) or stops commands (``tactile.required``).
"""

from conftest import ALLEGRO
from cycle_inputs import joint_state
from geometry_msgs.msg import WrenchStamped
from grasp_torque_opt.core.grasp_setup import GraspSetup
import numpy as np
import pytest
from rclpy.qos import qos_profile_sensor_data
from ros_harness import Harness
from std_msgs.msg import Float32MultiArray

SETUP = GraspSetup.from_file(ALLEGRO)
#: The V5 Sense's layout: palm, thumb (root, middle, tip), index, middle, ring (root,
#: second, third, tip); the bundled scenario's tip links.
V5_LINKS = ['', '', '', 'link_15.0_tip', '', '', '', 'link_3.0_tip', '', '', '',
            'link_7.0_tip', '', '', '', 'link_11.0_tip']
TIPS = {'link_15.0_tip': 3, 'link_3.0_tip': 7, 'link_7.0_tip': 11, 'link_11.0_tip': 15}


class TactileHarness(Harness):

    def __init__(self, source='array', **params):
        if source == 'array':
            params.setdefault('tactile__links', V5_LINKS)
        super().__init__(ALLEGRO, tactile__source=source, **params)
        topic, kind = (('tactile', Float32MultiArray) if source == 'array'
                       else ('tactile_wrench', WrenchStamped))
        self.source = topic
        self.tactile_pub = self.tester.create_publisher(kind, topic, qos_profile_sensor_data)
        assert self.spin_until(lambda: self.tactile_pub.get_subscription_count() > 0, 10.0)

    def send_array(self, data):
        self.tactile_pub.publish(Float32MultiArray(data=[float(x) for x in data]))
        self.spin_for(0.02)

    def send_wrench(self, link, force):
        msg = WrenchStamped()
        msg.header.frame_id = link
        f = msg.wrench.force
        f.x, f.y, f.z = (float(v) for v in force)
        self.tactile_pub.publish(msg)
        self.spin_for(0.02)

    def commands_after(self, n=3, timeout=2.0):
        k = len(self.commands)
        for _ in range(n):
            self.send_joint_state(*joint_state(SETUP))
            self.next_command(timeout)
        return [c for _, c in self.commands[k:]]

    def diag(self, predicate, timeout=3.0):
        assert self.spin_until(lambda: bool(self.diagnostics)
                               and predicate(self.diagnostics[-1]), timeout), \
            {k: v for k, v in self.diagnostics[-1].items() if 'tactile' in k or k in (
                'last_rejection', '_message')} if self.diagnostics else 'no diagnostics'
        return self.diagnostics[-1]


def tips(values):
    data = np.zeros(16)
    for link, v in values.items():
        data[TIPS[link]] = v
    return data


def test_the_array_is_read_and_a_lost_contact_reported():
    h = TactileHarness(tactile__timeout=10.0)
    try:
        nominal = h.commands_after()[-1]
        h.send_array(tips({'link_15.0_tip': 1.5, 'link_3.0_tip': 0.6, 'link_7.0_tip': 0.0,
                           'link_11.0_tip': 0.55}))
        h.commands_after(2)
        d = h.diag(lambda d: d.get('tactile.lost', 'none') != 'none')
        assert d['tactile.lost'].startswith('link_7.0_tip (0.000 N of 0.500 N planned)'), d
        assert d['contact1.link_7.0_tip.measured_friction_usage'] in ('inf', '0.0000'), d
        assert float(d['contact0.link_3.0_tip.measured_normal_force_N']) == pytest.approx(0.6)
        assert d['_level'] == 1 and 'contact lost: link_7.0_tip' in d['_message'], d
        # Reported, not commanded from: the commands are the certified ones of the state.
        for cmd in h.commands_after():
            np.testing.assert_allclose(cmd, nominal, atol=1e-9)
    finally:
        h.close()


BAD_ARRAYS = [
    ('NaN', lambda: tips({'link_3.0_tip': float('nan')}), 'tactile.data[7]: is not finite'),
    ('wrong length', lambda: np.zeros(15), 'tactile.data: has 15 entries, tactile.links '
     'maps 16'),
    ('pulling', lambda: tips({'link_11.0_tip': -1.0}), 'tactile.data[15]: is -1 N'),
    ('oversized force', lambda: tips({'link_3.0_tip': 500.0}),
     'tactile.data[7]: is 500 N, above tactile.max_force'),
    ('oversized message', lambda: np.zeros(20000), 'bytes serialized, more than '
     'max_message_bytes'),
]


def test_bad_arrays_are_rejected_named_and_never_used():
    h = TactileHarness(tactile__timeout=10.0)
    try:
        good = tips(dict.fromkeys(TIPS, 1.0))
        h.send_array(good)
        nominal = h.commands_after()[-1]
        h.diag(lambda d: d.get('tactile') == 'in use')
        for n, (what, data, why) in enumerate(BAD_ARRAYS, 1):
            h.send_array(data())
            cmds = h.commands_after()
            d = h.diag(lambda d: int(d.get('rejected.tactile', 0)) >= n)
            assert why in d['last_rejection'], (what, d['last_rejection'])
            assert why in h.node.controller.last_rejection
            for cmd in cmds:
                np.testing.assert_allclose(cmd, nominal, atol=1e-9)
            kept = h.node.controller.inputs.tactile
            assert {k: t.normal for k, t in kept.items()} == dict.fromkeys(TIPS, 1.0), what
            shown = {k: v for k, v in d.items() if 'measured' in k or 'tactile' in k}
            assert all(float(d[f'contact{i}.{c.link}.measured_normal_force_N']) == 1.0
                       for i, c in enumerate(SETUP.contacts)), (what, shown)
        assert h.node.controller.counters.rejected['tactile'] == len(BAD_ARRAYS)
    finally:
        h.close()


def test_an_unknown_or_unmapped_link_is_rejected_and_named():
    h = TactileHarness('wrench', tactile__links=['link_3.0_tip', 'link_7.0_tip'],
                       tactile__timeout=10.0)
    try:
        nominal = h.commands_after()[-1]
        h.send_wrench('link_3.0_tip', [0.0, 0.0, 1.0])
        bad = [('link_99_tip', "tactile_wrench.header.frame_id: 'link_99_tip' is not a link"),
               ('link_11.0_tip', "'link_11.0_tip' is not in tactile.links (unmapped)")]
        for n, (link, why) in enumerate(bad, 1):
            h.send_wrench(link, [0.0, 0.0, 1.0])
            cmds = h.commands_after()
            d = h.diag(lambda d: int(d.get('rejected.tactile_wrench', 0)) >= n)
            assert why in d['last_rejection'], d['last_rejection']
            for cmd in cmds:
                np.testing.assert_allclose(cmd, nominal, atol=1e-9)
        assert set(h.node.controller.inputs.tactile) == {'link_3.0_tip'}
        d = h.diag(lambda d: 'contact0.link_3.0_tip.measured_normal_force_N' in d)
        assert float(d['contact0.link_3.0_tip.measured_normal_force_N']) > 0.0
        assert 'link_7.0_tip' in d['tactile.stale'] and 'link_11.0_tip' in d['tactile.stale']
    finally:
        h.close()


def test_stale_tactile_is_said_or_a_fault_when_required():
    h = TactileHarness(tactile__timeout=0.1)
    try:
        h.send_array(tips(dict.fromkeys(TIPS, 1.0)))
        h.spin_for(0.3)
        assert len(h.commands_after()) == 3  # commands go on
        # The first report that says it (one a moment earlier, under load, may not yet).
        d = h.diag(lambda d: 'stale' in d.get('tactile', '') and d['_level'] == 1
                   and 'tactile stale' in d['_message'])
    finally:
        h.close()
    h = TactileHarness(tactile__timeout=0.1, tactile__required=True)
    try:
        assert h.commands_after(timeout=0.3) == []  # none received: a stale input
        assert h.commands_after(1, timeout=0.05) == []
        assert 'tactile stale (link_15.0_tip: none received' in h.node.controller.fault
        h.send_array(tips(dict.fromkeys(TIPS, 1.0)))
        assert len(h.commands_after(1)) == 1
        h.spin_for(0.3)
        assert h.commands_after(1, timeout=0.05) == []
        assert 'tactile stale (link_15.0_tip: ' in h.node.controller.fault
        assert 'tactile.required' in h.node.controller.fault
        d = h.diag(lambda d: d.get('tactile', '').startswith('stale: link_3.0_tip'))
        assert 'link_15.0_tip' in d['tactile.stale'], d
    finally:
        h.close()
