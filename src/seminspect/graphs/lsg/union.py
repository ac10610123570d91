"""The unified graph ``G_k``: the union of every local graph (000 eq (5)).

Every node and edge is registered in its local graph and merged into :class:`UnifiedGraph` in
the same step, so the unified graph is always the union ``V = ∪ V^l``, ``E = ∪ E^l``: a parent
node is held once however many local graphs count it, and an edge is stored under its canonical
key so both directions find it.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.graphs.lsg.model import Edge, EdgeKind, LocalGraph, Node, RobotNode


class UnifiedGraph:
    """The nodes and edges of ``G_k`` by id and canonical key, robot included."""

    def __init__(self, robot: RobotNode) -> None:
        self.nodes: dict[str, Node] = {robot.id: robot}
        self.edges: dict[tuple[str, str], Edge] = {}

    def add(self, local: LocalGraph, node: Node) -> None:
        """Register ``node`` in ``local`` and merge it into the unified graph (V and A union)."""
        if node.id in self.nodes and self.nodes[node.id] is not node:
            raise InvalidInputError(f"node id {node.id!r} already exists")
        local.nodes[node.id] = node
        self.nodes[node.id] = node

    def connect(
        self,
        local: LocalGraph,
        a: Node,
        b: Node,
        kind: EdgeKind,
        *,
        weight: float | None = None,
        via: NDArray[np.float64] | None = None,
    ) -> Edge:
        """Register an edge in ``local`` and merge it into the unified graph (E union)."""
        if weight is None:
            weight = (
                float(np.linalg.norm(a.position - b.position)) if kind is EdgeKind.SPATIAL else 0.0
            )
        u, v = (a.id, b.id) if a.id <= b.id else (b.id, a.id)
        edge = Edge(u, v, kind, weight, via)
        local.edges[edge.key] = edge
        self.edges[edge.key] = edge
        return edge

    def link(
        self,
        local: LocalGraph,
        a: Node,
        b: Node,
        via: ArrayLike | None,
        ends: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
    ) -> Edge:
        """A spatial edge realised by the polyline ``ends[0]``, ``via``, ``ends[1]`` (the two
        nodes' positions by default), weighing its length: the Euclidean distance when there is
        no ``via``. ``via`` is stored oriented along the edge's canonical key."""
        start, end = ends if ends is not None else (a.position, b.position)
        inner = (
            np.empty((0, 3)) if via is None else np.asarray(via, dtype=np.float64).reshape(-1, 3)
        )
        if not np.all(np.isfinite(inner)):
            raise InvalidInputError("via points must be finite")
        if a.id > b.id:  # orient along the canonical key, so the sum is reproducible
            a, b, start, end, inner = b, a, end, start, inner[::-1]
        polyline = np.vstack([start, inner, end])
        weight = float(np.linalg.norm(np.diff(polyline, axis=0), axis=1).sum())
        return self.connect(
            local, a, b, EdgeKind.SPATIAL, weight=weight, via=inner if len(inner) else None
        )

    def discard(self, local: LocalGraph, node_id: str) -> None:
        """Remove a child of ``local`` and its edges from ``local`` and the unified graph."""
        for key in [k for k in local.edges if node_id in k]:
            del local.edges[key]
            del self.edges[key]
        del local.nodes[node_id]
        del self.nodes[node_id]

    def remove(self, node_ids: Iterable[str]) -> None:
        """Remove nodes and every edge that touches them from the unified graph only, for a
        caller that drops the local graphs holding them as a whole."""
        gone = set(node_ids)
        for key in [k for k in self.edges if k[0] in gone or k[1] in gone]:
            del self.edges[key]
        for node_id in gone:
            del self.nodes[node_id]
