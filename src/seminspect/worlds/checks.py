"""Checks that a world suits a mission, made as the mission starts and before its heavy work.

A world without any object of the classes a mission inspects can still be explored, so it is
not an error; but a run that "completes" with 0 % detected and no word of why misleads, so the
mission says so in one warning line as it starts.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

from seminspect.worlds.world import World


class WorldWarning(UserWarning):
    """A world a mission can run in, though not to the end its user probably means."""


def warn_if_no_targets(world: World, classes: Sequence[str]) -> None:
    """Warn with a :class:`WorldWarning` when ``world`` holds no object of ``classes``, the
    classes the mission inspects: it will only explore."""
    if world.instances_of(*classes):
        return
    found = sorted({info.class_name for info in world.instances.values()})
    holds = f"it holds only {', '.join(found)}" if found else "it holds no objects"
    warnings.warn(
        f"world {world.name!r} has no targets ({', '.join(classes)}; {holds}): "
        "the mission will only explore",
        WorldWarning,
        stacklevel=2,
    )
