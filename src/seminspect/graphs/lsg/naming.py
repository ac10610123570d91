"""Stable, human-readable node names matching the operator queries of 000 Sec V-C.

Numbering rules:

* **Targets** are ``<label>-<k>``, where ``k`` is a zero-based counter over every target ever
  added to the graph, across labels, in the order the detections were registered (``car-0``,
  ``car-1``, ``truck-4`` as in 000 Table 5). Numbers are never reused, so a name keeps meaning
  one thing for the life of the graph.
* **Levels** are ``Level-<j>``, zero-based per target in the order they were inspected.
* **Poses** are ``pose-<n>``, zero-based per level in the order they were visited.
* **Features** are ``<label>-<m>``, one-based per label within a level (``hood-1``,
  ``front-left-light-2``), numbered when the level is closed and pruned by eq (10), in the order
  of the pose that observed them best.

Node ids in the unified graph join the names with ``/``: ``car-1/Level-0/hood-1``; the robot is
``robot``.
"""

from __future__ import annotations

import re

from seminspect.core.errors import InvalidInputError

SEPARATOR = "/"
ROBOT_ID = "robot"
_LABEL = re.compile(r"^[A-Za-z][A-Za-z0-9_ .-]{0,63}$")


def check_label(label: str) -> str:
    """A semantic label must be short text starting with a letter and contain no ``/``."""
    if not isinstance(label, str) or not _LABEL.match(label):
        raise InvalidInputError(
            f"invalid semantic label {label!r}: "
            "use up to 64 letters, digits, spaces, '-', '_' or '.', starting with a letter"
        )
    return label


def slug(label: str) -> str:
    """Label as it appears in a name: lower case, spaces replaced by hyphens."""
    return "-".join(label.lower().split())


def target_name(label: str, index: int) -> str:
    return f"{slug(label)}-{index}"


def level_name(index: int) -> str:
    return f"Level-{index}"


def pose_name(index: int) -> str:
    return f"pose-{index}"


def feature_name(label: str, ordinal: int) -> str:
    return f"{slug(label)}-{ordinal}"


def join(*names: str) -> str:
    return SEPARATOR.join(names)
