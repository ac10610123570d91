"""Operator queries in the grammar of 000 Sec V-C.

The paper's form is ``Visit <feature> in <level> of <target>``; shorter forms name fewer layers.
Accepted (case and spacing are free; ``Level 0`` equals ``level-0``)::

    Visit hood-1 in Level-0 of car-1      feature of a level of a target
    Observe wheel-1 in Level-0 of car-1   as Visit, then face the feature
    Visit hood-1 of car-1                 feature of a target (searched over its levels)
    Visit Level-1 of truck-16             a level
    Visit pose-3 in Level-0 of car-1      a view pose
    Visit car-1                           a target (its Level-0 entry point)

``go to`` and ``navigate to`` are synonyms of ``visit``; ``in``, ``of`` and ``at`` separate the
names, innermost first.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from enum import Enum

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.core.names import unknown_name
from seminspect.graphs.lsg import naming
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import FeatureNode, LevelNode, PoseNode


class Verb(str, Enum):
    VISIT = "visit"
    OBSERVE = "observe"


_VERBS = {
    "visit": Verb.VISIT,
    "go to": Verb.VISIT,
    "navigate to": Verb.VISIT,
    "observe": Verb.OBSERVE,
    "inspect": Verb.OBSERVE,
}
_VERBS_LONGEST_FIRST = sorted(_VERBS.items(), key=lambda item: -len(item[0]))
_SEPARATORS = re.compile(r"\s+(?:in|of|at)\s+")
_LEVEL = re.compile(r"^level-(\d+)$")
_NAME = re.compile(r"^[a-z][a-z0-9_.-]*$")
MAX_QUERY_LENGTH = 300


@dataclass(frozen=True, slots=True)
class Query:
    """A parsed query: names are normalised (lower case, hyphens) but not yet resolved."""

    verb: Verb
    target: str
    level: str | None = None
    node: str | None = None

    def __str__(self) -> str:
        parts = [self.node, self.level, self.target]
        names = [p for p in parts if p]
        joined = names[0] + "".join(
            f" {'in' if i == 0 and len(names) == 3 else 'of'} {n}" for i, n in enumerate(names[1:])
        )
        return f"{self.verb.value.capitalize()} {joined}"


def normalise_name(text: str) -> str:
    """``'Front Left  Light 2'`` -> ``'front-left-light-2'``; ``'LEVEL 0'`` -> ``'level-0'``."""
    return re.sub(r"-{2,}", "-", "-".join(text.strip().lower().split()))


def parse_query(text: str) -> Query:
    """Parse an operator query; malformed text raises :class:`InvalidInputError`."""
    if not isinstance(text, str) or not text.strip():
        raise InvalidInputError("empty query; try e.g. 'Visit hood-1 in Level-0 of car-1'")
    if len(text) > MAX_QUERY_LENGTH:
        raise InvalidInputError(f"query longer than {MAX_QUERY_LENGTH} characters")
    body = " ".join(text.strip().rstrip(".!?").split())
    verb, rest = _split_verb(body)
    names = [
        normalise_name(part) for part in _SEPARATORS.split(f" {rest} ".lower()) if part.strip()
    ]
    if not names:
        raise InvalidInputError(f"query {text!r} names no node; e.g. 'Visit car-1'")
    if len(names) > 3:
        raise InvalidInputError(
            f"query {text!r} names {len(names)} nodes; at most '<feature> in <level> of <target>'"
        )
    for name in names:
        if not _NAME.match(name):
            raise InvalidInputError(f"{name!r} in query {text!r} is not a node name")
    if _LEVEL.match(names[-1]):
        raise InvalidInputError(f"query {text!r} must end with a target, e.g. '... of car-1'")
    if len(names) == 3:
        if not _LEVEL.match(names[1]):
            raise InvalidInputError(f"{names[1]!r} is not a level name such as 'Level-0'")
        return Query(verb, target=names[2], level=names[1], node=names[0])
    if len(names) == 2:
        if _LEVEL.match(names[0]):
            return Query(verb, target=names[1], level=names[0])
        return Query(verb, target=names[1], node=names[0])
    return Query(verb, target=names[0])


def _split_verb(body: str) -> tuple[Verb, str]:
    lowered = body.lower()
    for phrase, verb in _VERBS_LONGEST_FIRST:
        if lowered == phrase:
            raise InvalidInputError(f"query {body!r} names no node; e.g. '{phrase} car-1'")
        if lowered.startswith(phrase + " "):
            return verb, body[len(phrase) + 1 :]
    first = body.split(maxsplit=1)[0]
    if first.lower() in {"go", "navigate", "move", "drive", "fly"}:
        raise InvalidInputError(f"unknown verb in {body!r}; use Visit, Observe, 'go to'")
    return Verb.VISIT, body


def resolve_query(graph: LayeredSemanticGraph, query: Query) -> str:
    """The id of the node a query names; unknown names list the closest valid ones."""
    target = graph.target(query.target)
    if query.level is None and query.node is None:
        return target.id
    levels = target.levels
    if not levels:
        raise PlanningError(f"{target.id} has not been inspected: it has no levels or features yet")
    if query.level is not None:
        by_name = {lv.name.lower(): lv for lv in levels}
        if query.level not in by_name:
            raise unknown_name("level", query.level, (lv.name for lv in levels), f"of {target.id}")
        scope = [by_name[query.level]]
    else:
        scope = levels
    if query.node is None:
        return scope[0].id
    # A pose or feature's id is its level's id joined with its (lower-case) name, so a lookup
    # by id finds it without scanning the level's nodes.
    matches = [
        node_id for level in scope if (node_id := naming.join(level.id, query.node)) in graph
    ]
    if len(matches) == 1:
        return matches[0]
    where = f"{scope[0].name} of {target.id}" if query.level else target.id
    if not matches:
        nodes = [node for level in scope for node in _named_nodes(level)]
        wanted = PoseNode if query.node.startswith("pose-") else FeatureNode
        names = [node.name for node in nodes if isinstance(node, wanted)]
        kind = "pose" if wanted is PoseNode else "feature"
        raise unknown_name(kind, query.node, names, f"in {where}")
    places = ", ".join(matches)
    raise InvalidInputError(f"{query.node!r} is ambiguous in {where} ({places}); name the level")


def _named_nodes(level: LevelNode) -> list[FeatureNode | PoseNode]:
    poses = level.poses
    return [feature for pose in poses for feature in pose.features] + poses
