"""Which parts a mission records as features: the world's own part names, never dropped silently.

A mission that does not set ``feature_labels`` takes the parts its world's targets carry, less
the parts that are the object itself (:data:`~seminspect.core.vocabulary.STRUCTURE_PARTS`:
``body``, ``roof``, ``wall``). As it starts, a mission says in one warning line each which
parts of its targets its labels leave out, which labels name no part of them, and when its
targets carry no parts to record at all.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Sequence

from seminspect.core.errors import InvalidInputError
from seminspect.core.vocabulary import KNOWN_FEATURES, STRUCTURE_PARTS
from seminspect.graphs.lsg.naming import check_label
from seminspect.worlds import World

#: How a user includes parts a mission leaves out (the setting is a MissionConfig field).
_HOW_TO_INCLUDE = (
    "add them to 'seminspect mission --features' (the setting feature_labels), or leave it "
    "unset to take every part the targets carry"
)


class FeatureWarning(UserWarning):
    """A mission's feature labels and its world's parts do not agree: some parts go unrecorded."""


def target_parts(world: World, classes: Iterable[str]) -> set[str]:
    """Every part name the world's objects of ``classes`` carry, structure included."""
    return {part for info in world.instances_of(*classes) for part in info.parts}


def world_feature_labels(world: World, classes: Iterable[str]) -> tuple[str, ...]:
    """The feature labels of a mission in ``world`` inspecting ``classes``.

    The targets' parts without the structure parts, in the built-in vocabulary's order and
    then alphabetically; a part name that cannot name a graph node (see
    :func:`~seminspect.graphs.lsg.naming.check_label`) is left out with a warning.
    """
    parts = target_parts(world, classes) - set(STRUCTURE_PARTS)
    known = [name for name in KNOWN_FEATURES if name in parts]
    labels = known + sorted(parts - set(known))
    unusable = [name for name in labels if not _is_label(name)]
    if unusable:
        warnings.warn(
            f"world {world.name!r}: part names {', '.join(map(repr, unusable))} cannot name "
            "features and are ignored; rename them in the labels file (a letter first, then "
            "letters, digits, spaces, '-', '_' or '.')",
            FeatureWarning,
            stacklevel=2,
        )
    return tuple(name for name in labels if name not in unusable)


def warn_about_feature_labels(world: World, classes: Sequence[str], labels: Sequence[str]) -> None:
    """Warn with a :class:`FeatureWarning` when the targets of ``world`` carry no parts to
    record, when ``labels`` leave out parts they carry (those go unrecorded), or when
    ``labels`` name parts that no target carries."""
    if not world.instances_of(*classes):
        return  # worlds.checks.warn_if_no_targets says so
    carried = target_parts(world, classes)
    structure = set(STRUCTURE_PARTS)
    if not carried - structure and not carried & set(labels):
        _warn(
            world,
            f"its targets carry no parts besides {', '.join(STRUCTURE_PARTS)}, so no features "
            "will be recorded; name their parts in the labels file ('part: ...')",
        )
        return
    ignored = sorted(carried - structure - set(labels))
    if ignored:
        _warn(
            world,
            "the feature labels leave out parts its targets carry, which will be ignored: "
            f"{', '.join(ignored)}; {_HOW_TO_INCLUDE}",
        )
    unmatched = [label for label in dict.fromkeys(labels) if label not in carried]
    if unmatched:
        _warn(
            world,
            f"no target carries the feature labels {', '.join(unmatched)}, so they will find "
            f"nothing; its targets' parts are {', '.join(sorted(carried))}",
        )


def _warn(world: World, message: str) -> None:
    warnings.warn(f"world {world.name!r}: {message}", FeatureWarning, stacklevel=3)


def _is_label(name: str) -> bool:
    try:
        check_label(name)
    except InvalidInputError:
        return False
    return True
