"""The exception hierarchy.

Every error a user can cause (a bad file, an unknown name, an impossible parameter) is a
:class:`SeminspectError`. The CLI turns these into one readable line and a non-zero exit code;
anything else is a bug.
"""

from __future__ import annotations


class SeminspectError(Exception):
    """Base class for errors caused by input, configuration or the state of the world."""


class InvalidInputError(SeminspectError, ValueError):
    """A value handed to the API is malformed: NaN pose, empty cloud, negative radius, ..."""


class FileFormatError(SeminspectError):
    """A file cannot be read: missing, truncated, malformed, hostile or of unsupported version."""


class UnknownNameError(SeminspectError, KeyError):
    """A name (node, world, preset, ...) does not exist; the message lists the closest ones."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


class PlanningError(SeminspectError):
    """No route exists, or the robot cannot be localised in the map or graph."""
