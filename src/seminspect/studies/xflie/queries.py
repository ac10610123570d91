"""Which operator queries the Table 5 comparison asks of a mission's final 3DLSG.

A query names a feature of an inspected target as an operator would ("Visit front-bumper-1 in
Level-0 of truck-4", 000 Table 5); the choice spreads the queries from the nearest to the
farthest target the robot can reach, and is deterministic.
"""

from __future__ import annotations

from collections.abc import Collection

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import FeatureNode, TargetNode, TargetStatus
from seminspect.planning.hierarchical import HierarchicalPlanner

#: Parts the paper's Table 5 queries name; a target's query asks for the first one it has.
PREFERRED_FEATURES = ("front-bumper", "back-left-door", "front-glass", "trunk", "front-right-door")


def select_queries(
    graph: LayeredSemanticGraph,
    start: ArrayLike,
    count: int = 9,
    reachable: Collection[str] | None = None,
) -> list[str]:
    """``count`` operator queries ("Visit <feature> in <level> of <target>") spread from the
    nearest to the farthest inspected target (by distance from ``start``), among the
    ``reachable`` targets when given.

    Targets are taken at evenly spaced ranks of distance; with fewer targets than queries each
    target is asked for again, for its next feature. A target's features are taken first ones
    first (``hood-1`` before ``hood-2``), in the order of :data:`PREFERRED_FEATURES`, then by
    name; the choice is deterministic.
    """
    if not (isinstance(count, int) and count >= 1):
        raise InvalidInputError(f"query count must be a positive integer, got {count!r}")
    origin = np.asarray(start, dtype=np.float64)
    targets = [
        t
        for t in graph.targets(TargetStatus.INSPECTED)
        if _features(t) and (reachable is None or t.id in reachable)
    ]
    if not targets:
        raise InvalidInputError("the graph has no inspected target with features to query")
    targets.sort(key=lambda t: (float(np.linalg.norm(t.position - origin)), t.id))
    menus = {t.id: _features(t) for t in targets}
    ranks = np.unique(np.round(np.linspace(0, len(targets) - 1, min(count, len(targets)))))
    order = [targets[int(r)] for r in ranks]
    queries: list[str] = []
    for round_ in range(max(len(m) for m in menus.values())):
        for target in order:
            menu = menus[target.id]
            if round_ < len(menu) and len(queries) < count:
                queries.append(_query_text(graph, target, menu[round_]))
    return queries


def _features(target: TargetNode) -> list[FeatureNode]:
    features = [f for level in target.levels for pose in level.poses for f in pose.features]
    return sorted(features, key=_preference)


def _preference(feature: FeatureNode) -> tuple[int, int, str]:
    """Every label's first feature before any second one; preferred labels first."""
    label = feature.label
    rank = (
        PREFERRED_FEATURES.index(label) if label in PREFERRED_FEATURES else len(PREFERRED_FEATURES)
    )
    return int(feature.name.rsplit("-", 1)[1]), rank, feature.id


def _query_text(graph: LayeredSemanticGraph, target: TargetNode, feature: FeatureNode) -> str:
    level = graph.node(graph.node(feature.pose_id).level_id)  # type: ignore[union-attr]
    return f"Visit {feature.name} in {level.name} of {target.id}"  # type: ignore[union-attr]


def reachable_targets(planner: HierarchicalPlanner, start: NDArray[np.float64]) -> set[str]:
    """Inspected targets the graph joins to where the robot is (the Target layer may be split
    where no route through known free space was found between inspected targets)."""
    found = set()
    for target in planner.graph.targets(TargetStatus.INSPECTED):
        try:
            planner.plan(target.id, start)
        except PlanningError:
            continue
        found.add(target.id)
    return found
