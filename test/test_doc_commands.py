# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Every shell command shown in the top-level *.md and docs/*.md runs as written, or says why not.

A fenced block is a command block when its language is ``bash``, ``sh``, ``shell`` or
``console``, when a line of it starts with ``$`` (a command and its output), or when
it is ``python``. Each needs a marker on the line before it:

    <!-- doc-test: run timeout=60 expect="held" -->
    <!-- doc-test: run stop_after=8 expect="cycle:" -->
    <!-- doc-test: run background expect="..." -->
    <!-- doc-test: skip reason="needs a real hand" -->

``run`` runs the block from the repository's root as a new user would (bash, one
command line at a time, each to exit 0; ``exit=N`` for the last one), within
``timeout`` seconds (default 60), and looks for each ``expect`` in its output (stdout
and stderr). ``stop_after=S`` stops a command that runs until stopped (a node) with
SIGINT S seconds after it is ready, which it must end on with exit 0: ready when its
output shows every ``expect`` (its start-up line; waited for up to ``timeout``, so a
slow start on a loaded machine is not stopped half-way). ``background`` starts the
block, waits until it is ready and ``wait`` seconds more (default 1), keeps it running
while the next ``run`` block of the page runs, then stops it as ``stop_after`` does. A
``python`` block runs as a script with ``.venv/bin/python``.
``skip`` needs a ``reason``. An unmarked command block fails.

The commands run in a scratch folder that links every entry of the repository (so the
files they write in the current folder stay out of the checkout), on a ROS domain of
this run with localhost-only discovery; a page's blocks share the folder and run in
page order.
"""

from dataclasses import dataclass
import os
from pathlib import Path
import re
import shlex
import signal
import subprocess
import time

import pytest
from ros_domains import domain

ROOT = Path(__file__).resolve().parents[1]
PAGES = [*sorted(ROOT.glob('*.md')), *sorted((ROOT / 'docs').glob('*.md'))]
SHELL_LANGUAGES = {'bash', 'sh', 'shell', 'console'}
MARKER = re.compile(r'^\s*<!--\s*doc-test:\s*(?P<body>.*?)\s*-->\s*$')
FENCE = re.compile(r'^(?P<indent>\s*)(?P<fence>```|~~~)(?P<lang>[\w+-]*)\s*$')
DEFAULT_TIMEOUT = 60.0
#: This run's domain for the documented commands (ros_domains.py).
DOMAIN = domain('doc_commands')


@dataclass
class Block:
    """One fenced command block of a page and its marker."""

    page: Path
    line: int
    language: str
    text: str
    marker: dict | None
    background: 'Block | None' = None

    @property
    def name(self) -> str:
        """Return the block's place, e.g. ``docs/node.md:11``."""
        return f'{self.page.relative_to(ROOT)}:{self.line}'

    def commands(self) -> list[str]:
        """Return the block's command lines, continuation lines joined."""
        lines = self.text.splitlines()
        if any(line.lstrip().startswith('$ ') for line in lines):
            # The `$ ` lines and their continuation lines; the rest is output.
            prompted, continued = [], False
            for line in lines:
                if continued or line.lstrip().startswith('$ '):
                    prompted.append(line if continued else line.lstrip()[2:])
                    continued = line.rstrip().endswith('\\')
            lines = prompted
        joined, current = [], ''
        for line in lines:
            if not current and (not line.strip() or line.lstrip().startswith('#')):
                continue
            if line.rstrip().endswith('\\'):
                current += line.rstrip()[:-1] + ' '
                continue
            joined.append(current + line)
            current = ''
        return joined


def parse_marker(body: str) -> dict:
    """Return a marker's action and options: ``run timeout=60 expect="a" expect="b"``."""
    words = shlex.split(body)
    if not words or words[0] not in ('run', 'skip'):
        raise ValueError(f'doc-test marker must start with run or skip: {body!r}')
    marker = {'action': words[0], 'expect': []}
    for word in words[1:]:
        key, _, value = word.partition('=')
        if key == 'expect':
            marker['expect'].append(value)
        elif key in ('timeout', 'stop_after', 'wait'):
            marker[key] = float(value)
        elif key == 'exit':
            marker[key] = int(value)
        elif key == 'background' and not value:
            marker[key] = True
        elif key == 'reason' and value:
            marker[key] = value
        else:
            raise ValueError(f'doc-test marker: unknown or empty option {key!r} in {body!r}')
    if marker['action'] == 'skip' and 'reason' not in marker:
        raise ValueError(f'doc-test skip needs a reason: {body!r}')
    return marker


def command_blocks(page: Path) -> list[Block]:
    """Return the command blocks of a page in order, each with its marker (or None)."""
    lines = page.read_text(encoding='utf-8').splitlines()
    blocks, i = [], 0
    while i < len(lines):
        match = FENCE.match(lines[i])
        if not match:
            i += 1
            continue
        start, body = i, []
        i += 1
        while i < len(lines) and not lines[i].strip().startswith(match['fence']):
            body.append(lines[i][len(match['indent']):])
            i += 1
        i += 1
        language = match['lang'].lower()
        is_command = (language in SHELL_LANGUAGES or language == 'python'
                      or any(line.lstrip().startswith('$ ') for line in body))
        if not is_command:
            continue
        previous = next((lines[j] for j in range(start - 1, -1, -1) if lines[j].strip()), '')
        found = MARKER.match(previous)
        blocks.append(Block(page, start + 1, language, '\n'.join(body),
                            parse_marker(found['body']) if found else None))
    return blocks


def all_blocks() -> list[Block]:
    """Return every page's command blocks, each background block attached to the next run."""
    result = []
    for page in PAGES:
        pending = None
        for block in command_blocks(page):
            if block.marker and block.marker['action'] == 'run':
                if block.marker.get('background'):
                    pending = block
                    continue
                block.background, pending = pending, None
            result.append(block)
    return result


BLOCKS = all_blocks()


@pytest.fixture(scope='session')
def scratch(tmp_path_factory) -> Path:
    """Return a folder that links every entry of the repository but .git."""
    folder = tmp_path_factory.mktemp('doc_commands')
    for entry in ROOT.iterdir():
        if entry.name != '.git':
            link = folder / entry.name
            link.symlink_to(entry)
            # The link's own time is its target's, so that scripts/setup.sh's
            # `find src -newer` sees the checkout's times, not the link's creation.
            times = entry.stat()
            os.utime(link, ns=(times.st_atime_ns, times.st_mtime_ns), follow_symlinks=False)
    return folder


def venv_is_current() -> bool:
    """Return whether scripts/setup.sh would only check (its stamp newer than its inputs)."""
    stamp = ROOT / '.venv' / '.installed'
    if not stamp.is_file():
        return False
    made = stamp.stat().st_mtime
    inputs = [ROOT / 'setup.py', ROOT / 'pyproject.toml', *(ROOT / 'src').rglob('*')]
    return all(p.stat().st_mtime <= made for p in inputs)


def environment() -> dict:
    """Return the commands' environment: this run's ROS domain, localhost discovery."""
    env = dict(os.environ, ROS_DOMAIN_ID=str(DOMAIN),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')
    env.pop('PYTHONPATH', None)
    return env


def start(command: list[str], cwd: Path, log: Path) -> subprocess.Popen:
    """Start a command in its own process group, its output in a file."""
    return subprocess.Popen(command, cwd=cwd, env=environment(), stdin=subprocess.DEVNULL,
                            stdout=log.open('wb'), stderr=subprocess.STDOUT,
                            start_new_session=True)


def stop(process: subprocess.Popen, grace: float = 20.0) -> int:
    """Send SIGINT to a command's process group and return its exit code."""
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGINT)
        try:
            process.wait(grace)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
            pytest.fail(f'{process.args} did not end within {grace} s of SIGINT')
    return process.returncode


def wait_ready(process: subprocess.Popen, log: Path, expect: list[str],
               timeout: float) -> None:
    """Wait until the output shows every ``expect`` line, or the command has ended."""
    deadline = time.monotonic() + timeout
    while process.poll() is None:
        output = log.read_text(errors='replace')
        if all(e in output for e in expect):
            return
        if time.monotonic() > deadline:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
            pytest.fail(f'{process.args[-1]!r} not ready (showing {expect}) within '
                        f'{timeout} s:\n{output[-3000:]}')
        time.sleep(0.1)


def run_command(command: list[str], cwd: Path, log: Path, timeout: float,
                stop_after: float | None, expect: list[str]) -> tuple[int, str]:
    """
    Run one command; return its exit and output.

    With ``stop_after``, SIGINT ``stop_after`` seconds after it is ready (``expect``).
    """
    process = start(command, cwd, log)
    if stop_after is not None:
        wait_ready(process, log, expect, timeout)
    try:
        process.wait(stop_after if stop_after is not None else timeout)
    except subprocess.TimeoutExpired:
        if stop_after is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
            pytest.fail(f'{command[-1]!r} took more than {timeout} s:\n'
                        + log.read_text(errors='replace')[-3000:])
    code = stop(process) if stop_after is not None else process.returncode
    return code, log.read_text(errors='replace')


def check_output(block: Block, output: str) -> None:
    """Fail unless every expected line is in the output."""
    for expected in block.marker['expect']:
        assert expected in output, (
            f'{block.name}: {expected!r} not in the output:\n{output[-3000:]}')


def run_block(block: Block, cwd: Path) -> None:
    """Run a block's commands in order, checking exits and output."""
    marker = block.marker
    log = cwd / f'.doc_test_{block.line}.log'
    if block.language == 'python':
        script = cwd / f'.doc_test_{block.page.stem}_{block.line}.py'
        script.write_text(block.text + '\n', encoding='utf-8')
        commands = [['.venv/bin/python', script.name]]
    else:
        commands = [['bash', '-c', line] for line in block.commands()]
    output_all = ''
    for n, command in enumerate(commands, 1):
        code, output = run_command(command, cwd, log, marker.get('timeout', DEFAULT_TIMEOUT),
                                   marker.get('stop_after'), marker['expect'])
        output_all += output
        want = marker.get('exit', 0) if n == len(commands) else 0
        assert code == want, (
            f'{block.name}: {command[-1]!r} exited {code}, not {want}:\n{output[-3000:]}')
    check_output(block, output_all)


def test_every_command_block_is_marked():
    """Fail for each command block without a marker: run it, or say why not."""
    unmarked = [block.name for page in PAGES for block in command_blocks(page)
                if block.marker is None]
    assert not unmarked, (
        'command blocks without a <!-- doc-test: run ... --> or <!-- doc-test: skip '
        'reason="..." --> marker on the line before: ' + ', '.join(unmarked))


@pytest.mark.parametrize('block', [b for b in BLOCKS if b.marker], ids=lambda b: b.name)
def test_documented_command(block: Block, scratch: Path):
    """Run a documented block as written (or skip it with its marker's reason)."""
    if block.marker['action'] == 'skip':
        pytest.skip(block.marker['reason'])
    assert venv_is_current(), (
        'run bash scripts/setup.sh first: the documented commands use its .venv/, and '
        'its install would otherwise run in the scratch folder')
    background = None
    if block.background is not None:
        command = block.background.commands()
        assert len(command) == 1, f'{block.background.name}: one command in the background'
        log = scratch / f'.doc_test_{block.background.line}.log'
        background = start(['bash', '-c', command[0]], scratch, log)
        marker = block.background.marker
        wait_ready(background, log, marker['expect'], marker.get('timeout', DEFAULT_TIMEOUT))
        time.sleep(marker.get('wait', 1.0))
    try:
        run_block(block, scratch)
    finally:
        if background is not None:
            code = stop(background)
            output = log.read_text(errors='replace')
            assert code == 0, (
                f'{block.background.name} exited {code} on SIGINT:\n{output[-3000:]}')
            check_output(block.background, output)
