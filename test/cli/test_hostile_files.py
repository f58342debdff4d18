# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Hostile scenario files through the CLI: exit 2 and one line naming the problem.

The answer comes in bounded time and memory, never as a traceback (an alias bomb took
over 4 GB, so did /dev/zero; 5000 levels of nesting raised RecursionError; a Latin-1
byte, UnicodeDecodeError; a directory as hand.urdf was "file not found").

The files are run in one child process whose address space is capped at 1.5 GB, so a
file that blows up kills the child, not the test run.
"""

from __future__ import annotations

import copy
import json
import os
import subprocess
import sys
import textwrap

from conftest import PLANAR, ROOT
import yaml

MEMORY_CAP = 1536 * 1024 * 1024
#: A file may take this long in the child (all of them take about a second here) [s].
TIME_CAP = 60


def chain_urdf(n: int) -> str:
    """Build a URDF of n revolute joints in a chain (170 KB at 500)."""
    inertia = ('<inertial><mass value="0.01"/><inertia ixx="1e-6" iyy="1e-6" izz="1e-6" '
               'ixy="0" ixz="0" iyz="0"/></inertial>')
    links = ['<link name="l0"/>'] + [f'<link name="l{i}">{inertia}</link>'
                                     for i in range(1, n + 1)]
    joints = [f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
              '<origin xyz="0 0.01 0"/><axis xyz="0 0 1"/>'
              '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
              for i in range(1, n + 1)]
    return f'<robot name="chain">{"".join(links)}{"".join(joints)}</robot>'


def bomb(levels: int) -> str:
    """Nested YAML aliases: 9**levels strings from a few hundred bytes."""
    parts = ['&a0 ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    parts += [f'&a{k} [' + ','.join([f'*a{k - 1}'] * 9) + ']' for k in range(1, levels)]
    return '[' + ', '.join(parts) + ']'


def hostile_files(tmp_path, planar_doc) -> list[tuple[str, str, str]]:
    """(label, path, expected field and problem) of every hostile file."""
    doc = copy.deepcopy(planar_doc)
    doc['hand']['urdf'] = str(PLANAR.parent / doc['hand']['urdf'])
    text = yaml.safe_dump(doc)
    out = []

    def write(label, content, expect, name=None):
        path = tmp_path / (name or f'{label}.yaml')
        (path.write_bytes if isinstance(content, bytes) else path.write_text)(content)
        out.append((label, str(path), expect))

    def with_field(label, section, key, value, expect):
        d = copy.deepcopy(doc)
        d[section][key] = value
        write(label, yaml.safe_dump(d), expect)

    bombed = text.replace('mu_tangential: 0.5', 'mu_tangential: ' + bomb(8))
    assert len(bombed) - len(text) < 1000  # 9**8 = 43 million strings from under 1 KB
    write('alias_bomb', bombed, 'scenario: YAML aliases are not allowed')
    write('small_bomb', text.replace('mu_tangential: 0.5', 'mu_tangential: ' + bomb(5)),
          'scenario: YAML aliases are not allowed')
    write('deep_nesting', text + 'junk: ' + '[' * 5000 + ']' * 5000 + '\n',
          'scenario: nested more than 16 levels deep')
    write('latin1_comment', b'# caf\xe9\n' + text.encode(), 'scenario: .* is not UTF-8 text '
          r'\(byte 0xe9 at offset 5\)')
    write('binary_garbage', bytes(range(256)) * 8, 'scenario: .* is not UTF-8 text')
    write('large_file', '# ' + 'x' * 300_000 + '\n' + text, 'scenario: .* is larger than '
          '262144 bytes')
    write('huge_integer', text.replace('mu_tangential: 0.5', 'mu_tangential: ' + '1' * 5000),
          'scenario: .* is not valid YAML: Exceeds the limit')
    out.append(('dev_zero', '/dev/zero', 'scenario: /dev/zero is not a regular file'))
    link = tmp_path / 'zero_link.yaml'
    link.symlink_to('/dev/zero')
    out.append(('symlink_to_dev_zero', str(link), 'scenario: .* is not a regular file'))
    fifo = tmp_path / 'fifo.yaml'
    os.mkfifo(fifo)
    out.append(('fifo', str(fifo), 'scenario: .* is not a regular file'))
    out.append(('directory', str(tmp_path), 'scenario: .* is a directory, not a file'))
    contacts = copy.deepcopy(doc['grasp']['contacts'][0])
    d = copy.deepcopy(doc)
    d['grasp']['contacts'] = [copy.deepcopy(contacts) for _ in range(1000)]
    write('1000_contacts', yaml.safe_dump(d), 'grasp.contacts: 1000 contacts, more than 32')
    with_field('20000_joint_names', 'hand', 'joints', [f'j{i}' for i in range(20000)],
               'hand.joints: 20000 names, more than 64')
    with_field('long_value', 'friction', 'mu_torsional', 'x' * 100_000,
               r"friction.mu_torsional: must be a number, got 'x{20}")
    (tmp_path / 'chain500.urdf').write_text(chain_urdf(500))
    d = copy.deepcopy(doc)
    d['hand'] = {'urdf': str(tmp_path / 'chain500.urdf'), 'torque_limits': 1.0}
    d['grasp']['joint_positions'] = {}
    d['grasp']['contacts'] = [{'link': 'l500'}, {'link': 'l250'}]
    write('500_joint_urdf', yaml.safe_dump(d), 'hand.urdf: the model has 500 degrees of '
          'freedom, more than 128')
    for label, urdf, expect in (('urdf_directory', str(tmp_path), 'hand.urdf: .* is a '
                                 'directory, not a file'),
                                ('urdf_device', '/dev/zero', 'hand.urdf: /dev/zero is not a '
                                 'regular file')):
        with_field(label, 'hand', 'urdf', urdf, expect)
    (tmp_path / 'latin1.urdf').write_bytes(
        b'<!-- caf\xe9 -->\n' + (ROOT / 'urdf' / 'planar_two_finger.urdf').read_bytes())
    with_field('urdf_latin1', 'hand', 'urdf', str(tmp_path / 'latin1.urdf'),
               'hand.urdf: .* is not UTF-8 text')
    return out


CHILD = textwrap.dedent("""
    import contextlib, io, json, resource, sys, time
    resource.setrlimit(resource.RLIMIT_AS, ({cap}, {cap}))
    from grasp_torque_opt.cli import main
    for path in sys.argv[1:]:
        err = io.StringIO()
        t0 = time.perf_counter()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
            code = main(["solve", path, "--json"])
        print(json.dumps([path, code, err.getvalue(), time.perf_counter() - t0]), flush=True)
""")


def test_hostile_files_exit_2_with_one_line_in_bounded_time_and_memory(tmp_path, planar_doc):
    import re

    files = hostile_files(tmp_path, planar_doc)
    done = subprocess.run([sys.executable, '-c', CHILD.format(cap=MEMORY_CAP)] +
                          [p for _, p, _ in files], capture_output=True, text=True,
                          timeout=TIME_CAP * 2)
    results = {r[0]: r[1:] for r in map(json.loads, done.stdout.splitlines())}
    for label, path, expect in files:
        assert path in results, f'{label}: the child died ({done.returncode}): ' \
                                f'{done.stderr[-2000:]}'
        code, err, seconds = results[path]
        lines = err.splitlines()
        assert code == 2 and len(lines) == 1, (label, code, err[:500])
        assert lines[0].startswith(f'grasp-torque-opt: error: {path}: '), (label, lines[0])
        assert re.search(expect, lines[0]), (label, lines[0])
        assert len(lines[0]) < 1000 and 'Traceback' not in err, label
        assert seconds < TIME_CAP, (label, seconds)
