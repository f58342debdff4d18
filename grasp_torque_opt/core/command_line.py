# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
What every console script shares: ``--help``, ``--version``, the exit-code table.

The scripts live in families that may not import each other (``cli`` and ``ros``),
so the help's format and the version option sit here, below both.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
import os
import sys

from grasp_torque_opt.core.exceptions import GraspTorqueError, InputError
from grasp_torque_opt.core.resources import package_version


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """
    argparse's defaults in the help, where there is one to show.

    ``(default: X)`` is added to an option's help unless its default is None or False
    (an absent option, a flag: the help says what then happens) or the help already
    states it.
    """

    def _get_help_string(self, action: argparse.Action) -> str:
        if action.default is None or action.default is False or 'default' in (action.help or ''):
            return action.help or ''
        return super()._get_help_string(action)


def add_version(parser: argparse.ArgumentParser) -> None:
    """Add ``--version``: the program's name and the package's version."""
    parser.add_argument('--version', action='version',
                        version=f'%(prog)s {package_version()} (grasp_torque_opt)')


#: The exit codes of every console script. docs/design.md section 4.2 freezes 0, 2, 3
#: and 4 for the CLI; 5 is ``plan``'s "fewer found"; 130 and 141 are the shell's own
#: for Ctrl-C and a reader gone (``| head``).
EXIT_OK, EXIT_BAD_INPUT, EXIT_INFEASIBLE, EXIT_FAILED, EXIT_FEWER = 0, 2, 3, 4, 5
EXIT_INTERRUPTED, EXIT_BROKEN_PIPE = 130, 141
#: An error -> its exit code, the first that matches; anything else is a bug and keeps
#: its traceback. Bad input (and input too large to process, which its bounds should
#: make unreachable) is the user's to fix; the rest is the package's or the system's.
ERRORS = (
    (InputError, EXIT_BAD_INPUT),
    (MemoryError, EXIT_BAD_INPUT),
    (RecursionError, EXIT_BAD_INPUT),
    (GraspTorqueError, EXIT_FAILED),
    (OSError, EXIT_FAILED),
)
#: Longest error line [characters].
MAX_ERROR_LENGTH = 2000


def one_line(text: str) -> str:
    r"""
    Escape every character that is not printable, line breaks included.

    A message quotes the user's input (a path, a name), and str.splitlines()
    breaks a line at \\x85 or \\u2028 as well as at \\n: the error stays one
    line whatever the input holds.
    """
    if len(text) > MAX_ERROR_LENGTH:  # every quoted value is cut already; a last bound
        text = text[:MAX_ERROR_LENGTH - 3] + '...'
    return ''.join(c if c.isprintable() else c.encode('unicode_escape').decode('ascii')
                   for c in text)


def error_line(prog: str, error: BaseException, where: str | None = None) -> str:
    """
    Return the one line an error prints: ``PROG: error: [WHERE: ]MESSAGE``.

    ``where`` (the file being read) prefixes bad input only: the input error names the
    field, the file says whose field it is.
    """
    if isinstance(error, (MemoryError, RecursionError)):
        text = f'scenario: too large to process ({type(error).__name__})'
    elif isinstance(error, OSError) and not isinstance(error, GraspTorqueError):
        text = f'{error.filename}: {error.strerror}' if error.filename else str(error)
    else:
        text = str(error)
    bad_input = isinstance(error, (InputError, MemoryError, RecursionError))
    return one_line(f'{prog}: error: {where}: {text}' if where and bad_input
                    else f'{prog}: error: {text}')


def run_command(prog: str, body: Callable[[], int],
                where: Callable[[], str | None] = lambda: None) -> int:
    """
    Run a console script's body and return its exit code, by :data:`ERRORS`.

    An error of the table prints its one line on stderr (:func:`error_line`, with
    ``where()`` at the time it was raised); Ctrl-C returns 130 without a traceback; a
    reader that went away (``| head``) returns 141 quietly, as Unix tools do, with
    stdout pointed at /dev/null so that Python's own flush at exit does not fail.
    """
    try:
        return body()
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_BROKEN_PIPE
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    except tuple(e for e, _ in ERRORS) as e:
        print(error_line(prog, e, where()), file=sys.stderr)
        return next(code for kind, code in ERRORS if isinstance(e, kind))
