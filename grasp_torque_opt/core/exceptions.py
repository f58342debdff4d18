# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Exceptions of grasp_torque_opt: one base class, subclasses that name the bad input."""

from collections.abc import Iterable
import reprlib

#: Longest quotation of the user's input in an error message [characters].
QUOTE_LENGTH = 80

_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxlist, _REPR.maxtuple, _REPR.maxdict = 2, 6, 6, 4
_REPR.maxstring = _REPR.maxother = QUOTE_LENGTH


def quote(value: object) -> str:
    """
    Return ``repr(value)`` cut to :data:`QUOTE_LENGTH` characters, in bounded time.

    The time is bounded whatever the value's size (a value quoted whole once printed a
    4.3 MB "one line").
    """
    text = _REPR.repr(value)
    return text if len(text) <= QUOTE_LENGTH else text[:QUOTE_LENGTH - 3] + '...'


#: Longest quotation of a path in an error message [characters].
PATH_LENGTH = 240


def cut(name: object, limit: int = QUOTE_LENGTH) -> str:
    """
    Quote a name from the input for messages: ``str(name)`` cut to ``limit`` characters.

    ``limit`` is :data:`PATH_LENGTH` for paths.
    """
    text = str(name) if not isinstance(name, str) else name
    return text if len(text) <= limit else text[:limit - 3] + '...'


class GraspTorqueError(Exception):
    """Base class of every error this package raises on purpose."""


class InputError(GraspTorqueError):
    """
    An input value is invalid.

    Attributes:
        field: dotted path of the offending input, e.g. ``grasp.contacts[1].normal``.
        problem: what is wrong with it, in a few words.
    """

    def __init__(self, field: str, problem: str) -> None:
        self.field = field
        self.problem = problem
        super().__init__(f'{field}: {problem}')


def _choices(available: Iterable[str], limit: int = 12) -> str:
    names = sorted(available)
    shown = ', '.join(cut(n) for n in names[:limit])
    return shown + (f', ... ({len(names)} in all)' if len(names) > limit else '')


class FrameNotFound(InputError):
    """A frame name is not in the model."""

    def __init__(self, field: str, name: str, available: Iterable[str]) -> None:
        self.name = name
        self.available = sorted(available)
        super().__init__(field,
                         f"unknown frame '{cut(name)}' (model frames: "
                         f'{_choices(self.available)})')


class JointNotFound(InputError):
    """A joint name is not in the model, or is not a one-degree-of-freedom joint."""

    def __init__(self, field: str, name: str, available: Iterable[str]) -> None:
        self.name = name
        self.available = sorted(available)
        super().__init__(
            field, f"unknown joint '{cut(name)}' (1-DoF joints: {_choices(self.available)})"
        )


class SolverError(GraspTorqueError):
    """A solver raised or could not be set up; the original error is chained."""
