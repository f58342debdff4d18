# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""A suite run under a chosen ROS_DOMAIN_ID puts its nodes on that base's domains only."""

import os
import subprocess
import sys
import time

from conftest import ROOT
from grasp_torque_opt.ros.domains import base, MAX_DOMAIN, private, SPAN
import pytest
import rclpy
from ros_domains import BASE, ROLES

#: Two tests of the suite, one with the harness's in-process node, one with a script's.
INNER = ['test/ros/test_node.py::'
         'test_the_compiled_cycle_answers_over_ros_and_the_parameter_turns_it_off',
         'test/ros/test_without_optional_solvers.py']


def test_roles_have_distinct_domains_within_the_span():
    offsets = list(ROLES.values()) + [ROLES['sim_listen'] + 1, ROLES['sim_listen'] + 2]
    assert len(set(offsets)) == len(offsets) and min(offsets) >= 1 and max(offsets) <= SPAN
    assert BASE + SPAN <= MAX_DOMAIN


def test_a_run_under_a_chosen_domain_uses_that_bases_domains():
    chosen = BASE + SPAN if BASE + 2 * SPAN <= MAX_DOMAIN else BASE - SPAN
    watched = {chosen: 'base', chosen + ROLES['in_process']: 'in_process',
               chosen + ROLES['without_optional']: 'without_optional'}
    # Heard as the suite's processes are: discovery on localhost only.
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    contexts, nodes = {}, {}
    for d in watched:
        contexts[d] = rclpy.Context()
        rclpy.init(context=contexts[d], domain_id=d)
        nodes[d] = rclpy.create_node(f'domain_watcher_{d}', context=contexts[d])
    time.sleep(1.0)  # the watchers' discovery settled before the run starts
    env = dict(os.environ, ROS_DOMAIN_ID=str(chosen), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    env.pop('PYTEST_ADDOPTS', None)
    seen = {d: set() for d in watched}
    try:
        # The inner nodes live a second or two: a watcher may miss one in discovery, so
        # up to three runs until both roles were seen; the base must stay empty in all.
        for _ in range(3):
            inner = subprocess.Popen([sys.executable, '-m', 'pytest', '-q', '-p',
                                      'no:cacheprovider', *INNER], cwd=ROOT, env=env,
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True)
            while inner.poll() is None:
                for d, node in nodes.items():
                    seen[d].update(n for n in node.get_node_names()
                                   if not n.startswith('domain_'))
                time.sleep(0.05)
            out = inner.communicate(timeout=300)[0]
            assert inner.returncode == 0, out[-3000:]
            by_role = {watched[d]: sorted(names) for d, names in seen.items()}
            if by_role['in_process'] and by_role['without_optional']:
                break
    finally:
        for d in watched:
            nodes[d].destroy_node()
            rclpy.shutdown(context=contexts[d])
    # A node that lives a second may go unseen by discovery on a loaded machine (the two
    # roles were each missed once in three runs here): one role seen is the evidence
    # that the run's nodes are on the base's domains; the harness's own domains are
    # checked as computed under the same environment, and the base stays empty.
    assert 'grasp_torque_node' in by_role['in_process'] + by_role['without_optional'], by_role
    assert not by_role['base'], f'a node on ROS_DOMAIN_ID itself: {by_role}'
    done = subprocess.run([sys.executable, '-c', 'import ros_harness as h; '
                           'print(h.DOMAIN, h.PROCESS_DOMAIN)'], cwd=ROOT / 'test', env=env,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert [int(v) for v in done.stdout.split()] == [chosen + ROLES['in_process'],
                                                     chosen + ROLES['process']]


@pytest.mark.parametrize('bad', ['-1', str(MAX_DOMAIN - SPAN + 1)])
def test_a_domain_id_without_room_for_the_span_is_refused(bad):
    done = subprocess.run([sys.executable, '-c', 'import ros_domains'], cwd=ROOT / 'test',
                          env=dict(os.environ, ROS_DOMAIN_ID=bad), capture_output=True,
                          text=True, timeout=60)
    assert done.returncode != 0 and f'ROS_DOMAIN_ID {bad}:' in done.stderr, done.stderr


def test_the_drivers_and_benchmarks_private_domains_follow_the_same_rule():
    """--with-node and the benchmarks: ROS_DOMAIN_ID + 1 on, never it, never random."""
    assert [private(k, {'ROS_DOMAIN_ID': '40'}) for k in (0, 1, 11, 12)] == [41, 42, 52, 41]
    # Without ROS_DOMAIN_ID: a multiple of SPAN from the process id, the same each time.
    assert base({}, pid=12345) == base({}, pid=12345) == SPAN * (12345 % 19)
    assert all(0 <= base({}, pid=p) <= MAX_DOMAIN - SPAN for p in range(0, 5000, 7))
    env = {k: v for k, v in os.environ.items() if k != 'ROS_DOMAIN_ID'}
    code = ('import os; from grasp_torque_opt.ros.node_process import isolate; isolate(); '
            'print(os.getpid(), os.environ["ROS_DOMAIN_ID"])')
    done = subprocess.run([sys.executable, '-c', code], env=env, capture_output=True,
                          text=True, timeout=60, cwd=ROOT)
    pid, chosen = (int(v) for v in done.stdout.split())
    assert chosen == base({}, pid=pid) + 1
    done = subprocess.run([sys.executable, '-c', 'import sys; sys.path.insert(0, "bench"); '
                           'from ros_load import private_domains; print(*private_domains(14))'],
                          env=dict(os.environ, ROS_DOMAIN_ID='40'), capture_output=True,
                          text=True, timeout=60, cwd=ROOT)
    assert [int(v) for v in done.stdout.split()] == [*range(41, 53), 41, 42], done.stderr
