"""Exceptions of grasp_torque_opt: one base class, subclasses that name the bad input."""

from collections.abc import Iterable


class GraspTorqueError(Exception):
    """Base class of every error this package raises on purpose."""


class InputError(GraspTorqueError):
    """An input value is invalid.

    Attributes:
        field: dotted path of the offending input, e.g. ``grasp.contacts[1].normal``.
        problem: what is wrong with it, in a few words.
    """

    def __init__(self, field: str, problem: str) -> None:
        self.field = field
        self.problem = problem
        super().__init__(f"{field}: {problem}")


def _choices(available: Iterable[str], limit: int = 12) -> str:
    names = sorted(available)
    shown = ", ".join(names[:limit])
    return shown + (f", ... ({len(names)} in all)" if len(names) > limit else "")


class FrameNotFound(InputError):
    """A frame name is not in the model."""

    def __init__(self, field: str, name: str, available: Iterable[str]) -> None:
        self.name = name
        self.available = sorted(available)
        super().__init__(field,
                         f"unknown frame '{name}' (model frames: {_choices(self.available)})")


class JointNotFound(InputError):
    """A joint name is not in the model, or is not a one-degree-of-freedom joint."""

    def __init__(self, field: str, name: str, available: Iterable[str]) -> None:
        self.name = name
        self.available = sorted(available)
        super().__init__(
            field, f"unknown joint '{name}' (1-DoF joints: {_choices(self.available)})"
        )


class SolverError(GraspTorqueError):
    """A solver raised or could not be set up; the original error is chained."""
