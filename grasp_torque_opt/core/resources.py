# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
Where the package's bundled files are, and how any input file is read.

The bundled files (config/, urdf/) are found installed or in the source tree; an input
file is read only if it is a regular file, within a size bound.
"""

from __future__ import annotations

import os
from pathlib import Path
import re
import stat
import sys

from grasp_torque_opt.core.exceptions import cut, InputError, PATH_LENGTH

PACKAGE = 'grasp_torque_opt'


def config_dirs() -> list[Path]:
    """Candidate config/ folders: installed shares (ROS prefixes, this Python), then the source."""
    prefixes = [p for p in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p]
    dirs = [Path(p) / 'share' / PACKAGE / 'config' for p in prefixes + [sys.prefix]]
    dirs.append(Path(__file__).resolve().parents[2] / 'config')  # grasp_torque_opt/core/ -> root
    return [d for d in dirs if d.is_dir()]


def find_config(name: str, field: str = 'scenario') -> Path:
    """
    Find a file given as a path, or by name among the bundled config files.

    Raises:
        InputError: naming ``field``, when neither exists.
    """
    path = Path(name).expanduser()
    if os.path.exists(path):  # False on any OSError, e.g. a name too long
        return path  # a directory or device is refused by its reader, saying so
    if not path.is_absolute():
        for d in config_dirs():
            if (d / path).is_file():
                return d / path
    raise InputError(field, f'file not found: {cut(name, PATH_LENGTH)} '
                     f"(nor in {', '.join(map(str, config_dirs()))})")


def package_version() -> str:
    """
    Return the package's version: its installed metadata, else package.xml's ``<version>``.

    Every console script's ``--version`` prints it.
    """
    from importlib import metadata

    try:
        return metadata.version(PACKAGE)
    except metadata.PackageNotFoundError:  # a colcon build without pip metadata
        pass
    prefixes = [p for p in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p]
    for xml in [Path(p) / 'share' / PACKAGE / 'package.xml' for p in prefixes + [sys.prefix]] \
            + [Path(__file__).resolve().parents[2] / 'package.xml']:
        if xml.is_file():
            found = re.search(r'<version>\s*([^<\s]+)\s*</version>', xml.read_text())
            if found:
                return found.group(1)
    return 'unknown'


def read_bounded(path: Path, field_name: str, limit: int) -> bytes:
    """
    Read the bytes of a regular file of at most ``limit`` bytes.

    Opened without blocking and checked on the open descriptor, so a device, a
    pipe or a symlink to one is refused before anything is read (``/dev/zero``
    as a scenario took over 4 GB in 5 s), and at most ``limit + 1`` bytes are
    read whatever the file does meanwhile.

    Raises:
        InputError: naming ``field_name``: cannot be opened, not a regular file,
            or too large.
    """
    shown = cut(path, PATH_LENGTH)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except OSError as e:
        raise InputError(field_name, f'cannot read {shown}: {e.strerror}') from e
    try:
        mode = os.fstat(fd).st_mode
        if stat.S_ISDIR(mode):
            raise InputError(field_name, f'{shown} is a directory, not a file')
        if not stat.S_ISREG(mode):
            raise InputError(field_name, f'{shown} is not a regular file (a device, pipe or '
                             'socket)')
        chunks, left = [], limit + 1
        while left > 0:
            chunk = os.read(fd, left)
            if not chunk:
                break
            chunks.append(chunk)
            left -= len(chunk)
        data = b''.join(chunks)
    except OSError as e:
        raise InputError(field_name, f'cannot read {shown}: {e.strerror}') from e
    finally:
        os.close(fd)
    if len(data) > limit:
        raise InputError(field_name, f'{shown} is larger than {limit} bytes')
    return data


def decode_utf8(data: bytes, path: Path, field_name: str) -> str:
    """UTF-8 text, or an error that says where the first bad byte is."""
    shown = cut(path, PATH_LENGTH)
    try:
        return data.decode('utf-8')
    except UnicodeDecodeError as e:
        raise InputError(field_name, f'{shown} is not UTF-8 text (byte 0x{data[e.start]:02x} '
                         f'at offset {e.start})') from e
