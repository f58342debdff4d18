# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
grasp-torque-sim --lockstep, --rotation-limit and --friction-scale, with the real node.

Lockstep runs wait for the node's answer to each joint state in simulated time, so
that two runs of one case give the same printed outcome, digit for digit.
"""

import re
import subprocess
import sys

from test_sim_driver import _command, run, summary_of

#: 1 g static along +y at Kp 0.3, 1 s: the cell issue 32 found unreproducible in real time.
CELL = ('--with-node', '--lockstep', '--no-picture', '--base-accel', '0,9.81,0', '--kp', '0.3',
        '--duration', '1')


def _physics(done):
    """Return the per-second lines and the outcome, without wall-clock figures."""
    lines = [line for line in done.stdout.splitlines() if line.startswith('t=')]
    summary = summary_of(done)
    outcome = summary.split('; mean effort')[0]
    return lines, outcome, summary


def test_lockstep_runs_of_the_same_case_give_the_same_outcome_twice():
    first, second = run(*CELL), run(*CELL)
    assert first.returncode in (0, 1) and second.returncode == first.returncode, \
        first.stderr + second.stderr
    lines_a, outcome_a, summary_a = _physics(first)
    lines_b, outcome_b, summary_b = _physics(second)
    assert lines_a and lines_a == lines_b
    assert outcome_a == outcome_b
    # Every joint state answered, and one command per joint state (250 Hz for 1 s).
    for summary in (summary_a, summary_b):
        assert 'lockstep, 0 joint states unanswered' in summary, summary
        assert int(re.search(r'; (\d+) commands', summary).group(1)) == 250, summary


def test_a_ball_turned_beyond_the_rotation_limit_is_not_held():
    case = ('--with-node', '--lockstep', '--no-picture', '--object-offset', '0,-5,0',
            '--kp', '0.3', '--duration', '0.5')
    loose = run(*case, '--rotation-limit', '90', '--drift-limit', '50')
    assert loose.returncode == 0, loose.stdout + loose.stderr
    summary = summary_of(loose)
    rotation = float(re.search(r'rotation ([0-9.]+) deg', summary).group(1))
    assert rotation > 0.01, summary
    # The same run (lockstep) against a rotation limit below what it turned.
    tight = run(*case, '--rotation-limit', f'{rotation / 2:g}', '--drift-limit', '50')
    assert tight.returncode == 1, tight.stdout + tight.stderr
    summary = summary_of(tight)
    assert summary.startswith(f'summary: NOT held: rotation {rotation:.3f} deg after 0.5 s, '
                              f'not under the rotation limit {rotation / 2:g} deg'), summary


#: The simulated hand of grasp-torque-sim whose /clock reaches the node after the joint
#: state on every third step, as the middleware may deliver two topics (no order between
#: them is sure): a node that took the clock for the cycle's time saw no time pass there.
LATE_CLOCK = """
import itertools, sys
from grasp_torque_opt.ros import sim_driver
tick, publish, count = sim_driver._Link.tick, sim_driver._Link.publish, itertools.count()

def late_tick(self):
    self.late = next(count) % 3 == 1
    if not self.late:
        tick(self)

def late_publish(self):
    if getattr(self, 'late', False):
        self.late = False
        self.state['clock'] = round(self.hsim.time * 1e9)  # not before the joint state
        publish(self)
        tick(self)
    else:
        publish(self)

sim_driver._Link.tick, sim_driver._Link.publish = late_tick, late_publish
sys.exit(sim_driver.main(sys.argv[1:]))
"""


def test_a_clock_that_comes_after_the_joint_state_changes_nothing():
    # A 5 mm offset at Kp 0.3: the object loop and the rate rule both act, and both
    # count time (a cycle that saw none once reset the loop: 2.3 deg against 1.4).
    case = ('--with-node', '--lockstep', '--no-picture', '--object-offset', '0,-5,0',
            '--kp', '0.3', '--duration', '0.5', '--rotation-limit', '90')
    plain = run(*case)
    command, env = _command(case)
    late = subprocess.run([sys.executable, '-c', LATE_CLOCK, *command[3:]],
                          capture_output=True, text=True, timeout=120, env=env)
    assert plain.returncode == 0 and late.returncode == 0, late.stdout + late.stderr
    assert _physics(late)[:2] == _physics(plain)[:2]


def test_bad_friction_scales_and_limits_give_one_line_and_exit_2():
    cases = {('--friction-scale', '0'): '--friction-scale: must be > 0',
             ('--friction-scale', '-0.7'): '--friction-scale: must be > 0',
             ('--friction-scale', 'nan'): '--friction-scale: must be > 0',
             ('--friction-scale', 'inf'): '--friction-scale: must be finite',
             ('--friction-scale', '0.7', '--mu-tangential', '0.4'):
                 '--friction-scale: not with --mu-tangential or --mu-torsional (give the '
                 'scale of both, or the values)',
             ('--friction-scale', '0.7', '--mu-torsional', '0.001'):
                 '--friction-scale: not with --mu-tangential or --mu-torsional (give the '
                 'scale of both, or the values)',
             ('--rotation-limit', '0'): '--rotation-limit: must be > 0',
             ('--lockstep', '--controller', 'preset'):
                 '--lockstep: only with --controller node (got preset)'}
    for args, message in cases.items():
        done = run(*args, timeout=60)
        assert done.returncode == 2 and done.stdout == '', (args, done.stderr)
        assert done.stderr == f'grasp-torque-sim: error: {message}\n', args
