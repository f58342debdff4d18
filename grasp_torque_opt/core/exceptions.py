# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Exceptions of grasp_torque_opt: one base class, subclasses that name the bad input."""

from collections.abc import Iterable
import difflib
import os
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


#: Closest names suggested for an unknown one (difflib's ratio of at least 0.6).
SUGGESTIONS = 3


def _choices(available: list[str], limit: int = 12) -> str:
    shown = ', '.join(cut(n) for n in available[:limit])
    return shown + (f', ... ({len(available)} in all)' if len(available) > limit else '')


def _ordered(available: Iterable[str]) -> list[str]:
    """Keep a sequence's order (the relevant names first); sort a set."""
    if isinstance(available, (set, frozenset)):
        return sorted(available)
    return list(dict.fromkeys(available))


def _closest(name: str, available: list[str]) -> str:
    """Suggest the closest names: difflib's ratio (>= 0.6), ties to the longest common prefix."""
    scored = []
    for n in available:
        ratio = difflib.SequenceMatcher(None, name, n).ratio()
        if ratio >= 0.6:
            prefix = len(os.path.commonprefix([name, n]))
            scored.append((-ratio, -prefix, n))
    close = [n for _, _, n in sorted(scored)[:SUGGESTIONS]]
    return f"did you mean {' or '.join(repr(cut(n)) for n in close)}? " if close else ''


class FrameNotFound(InputError):
    """
    A frame name is not in the model.

    Attributes:
        name: the unknown name.
        available: the model's frames, the relevant first (the caller's order: links,
            then joint and other frames).
    """

    def __init__(self, field: str, name: str, available: Iterable[str]) -> None:
        self.name = name
        self.available = _ordered(available)
        super().__init__(field,
                         f"unknown frame '{cut(name)}' ({_closest(name, self.available)}"
                         f'model frames: {_choices(self.available)})')


class JointNotFound(InputError):
    """A joint name is not in the model, or is not a one-degree-of-freedom joint."""

    def __init__(self, field: str, name: str, available: Iterable[str]) -> None:
        self.name = name
        self.available = _ordered(available)
        super().__init__(
            field, f"unknown joint '{cut(name)}' ({_closest(name, self.available)}"
                   f'1-DoF joints: {_choices(self.available)})'
        )


class SolverError(GraspTorqueError):
    """A solver raised or could not be set up; the original error is chained."""


class GeometryError(InputError):
    """
    The contact geometry cannot give contacts: no collision shape, a bad mesh, overlap.

    Raised by :mod:`grasp_torque_opt.core.geometry_contacts`: a contact link without
    collision geometry, a degenerate object mesh, an object inside a link (or a link
    inside it, or deeper in it than the bound). ``field`` names the input.
    """


class GeometryWarning(UserWarning):
    """A contact written by hand is farther from the object's surface than the tolerance."""
