"""Hierarchical and semantic path planning over the 3DLSG (000 Sec V-C).

A query is answered in three steps, as in the paper:

1. **Localise** the robot in the layers: the nearest traversable node (a level or view pose of
   an inspected target) gives the current target ``v_curr^T``, level ``v_curr^L`` and pose
   ``v_curr^P``.
2. **Global route** ``Π(v_curr^T, v_trm^T)`` over the Target layer: A* over the spatial
   ``v_I - v_I`` edges.
3. **Local routes** over the Level and Pose graphs of the start target (from the robot's pose to
   the target's ``Level-0`` node) and of the terminal target (from its ``Level-0`` node to the
   queried node), then the metric waypoints.

Every target's local graph meets the Target layer at one node, its ``Level-0`` (where its
inspection started), and the ``v_I - v_I`` edges join those entry nodes. Each entry node is
therefore a cut vertex of the traversable graph, so the three searches return exactly the
shortest path of a Dijkstra search over the whole flattened graph, while touching only the
Target layer and two small local graphs.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from itertools import pairwise

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import PlanningError
from seminspect.geometry.nearest import NearestIndex
from seminspect.geometry.transforms import as_point, yaw_from_quat
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import (
    Edge,
    EdgeKind,
    FeatureNode,
    LevelNode,
    Node,
    PoseNode,
    TargetNode,
    TargetStatus,
)
from seminspect.planning.graph_astar import CsrGraph, shortest_path, warm_up
from seminspect.planning.query import Query, Verb, parse_query, resolve_query


@dataclass(frozen=True, slots=True)
class Localisation:
    """Where the robot is in the layers: ``v_curr^T``, ``v_curr^L``, ``v_curr^P``."""

    target_id: str
    level_id: str
    pose_id: str | None
    node_id: str
    distance: float


@dataclass(frozen=True, slots=True)
class PlanTiming:
    """Wall-clock seconds spent per step of one query."""

    localise_s: float
    target_layer_s: float
    local_layers_s: float
    total_s: float


@dataclass(frozen=True)
class RoutePlan:
    """The planner's answer: the route per layer, the metric path, its cost and timing."""

    goal_id: str
    #: The feature to observe at the end, when the query named one.
    terminal_id: str | None
    start: NDArray[np.float64]
    localisation: Localisation
    #: Target-layer route, current target first.
    target_route: tuple[str, ...]
    #: Every traversable node (levels and poses) in order.
    node_path: tuple[str, ...]
    #: Metric path: the start position, then every node and via point (K x 3).
    waypoints: NDArray[np.float64]
    #: Graph cost from the localised node to the goal node.
    cost: float
    #: Sum of the Target-layer edge weights along the global route.
    target_layer_length: float
    timing: PlanTiming
    #: Nodes settled by all searches together (the graph size the query touched).
    settled: int
    #: Heading to hold at the end (facing the observed feature or target), if any.
    final_yaw: float | None = None
    query: str | None = None
    level_route: tuple[str, ...] = field(default=())
    pose_route: tuple[str, ...] = field(default=())

    @property
    def length(self) -> float:
        """Metric length of the waypoint path (the first leg from the start included)."""
        return float(np.linalg.norm(np.diff(self.waypoints, axis=0), axis=1).sum())


@dataclass(slots=True)
class _LocalIndex:
    """The traversable part of one target's local graphs (its levels and poses) in CSR form."""

    node_ids: list[str]
    index: dict[str, int]
    csr: CsrGraph
    #: Nodes ``0 .. n_levels - 1`` are levels (``Level-0`` first), the rest are poses.
    n_levels: int
    #: Via points of edges realised by a polyline, by (from, to) node, in travel order.
    vias: dict[tuple[int, int], NDArray[np.float64]]

    def points(self, nodes: NDArray[np.int64]) -> NDArray[np.float64]:
        """The metric path through ``nodes``: their positions and any via points between."""
        coords = self.csr.coords[nodes]
        if not self.vias:
            return coords
        chunks = [coords[:1]]
        for k, step in enumerate(pairwise(nodes.tolist())):
            via = self.vias.get(step)
            if via is not None:
                chunks.append(via)
            chunks.append(coords[k + 1 : k + 2])
        return np.concatenate(chunks)


@dataclass(slots=True)
class _Network:
    """Search structures for one graph revision."""

    revision: int
    target_ids: list[str]
    target_index: dict[str, int]
    target_csr: CsrGraph
    target_edges: dict[tuple[int, int], Edge]
    locals: list[_LocalIndex]
    nearest: NearestIndex | None
    owner: NDArray[np.int64]
    local_of: NDArray[np.int64]

    # A route is the target hops of the global search with one local segment (same target) or
    # two (out of the first target to its Level-0, from the last target's Level-0 to the goal).
    def route_points(
        self, origin: NDArray[np.float64], hops: list[int], segments: list[NDArray[np.int64]]
    ) -> tuple[NDArray[np.float64], float]:
        """The route's metric path from ``origin``, via points included, and the summed weight
        of its Target-layer edges."""
        chunks = [origin[None, :], self.locals[hops[0]].points(segments[0])]
        target_length = 0.0
        for a, b in pairwise(hops):
            edge = self.target_edges[(a, b)]
            target_length += edge.weight
            if edge.via is not None:
                forward = self.target_ids[a] == edge.u
                chunks.append(edge.via if forward else edge.via[::-1])
            chunks.append(self.locals[b].csr.coords[:1])
        if len(segments) > 1:
            chunks.append(self.locals[hops[-1]].points(segments[1])[1:])
        return np.concatenate(chunks), target_length

    def route_nodes(
        self, hops: list[int], segments: list[NDArray[np.int64]]
    ) -> tuple[list[str], list[str], list[str]]:
        """The ids of the route's traversable nodes in order: all of them, its levels, its
        poses."""
        visits = [(hops[0], segments[0].tolist()), *((b, [0]) for b in hops[1:])]
        if len(segments) > 1:
            visits.append((hops[-1], segments[1][1:].tolist()))
        ids: list[str] = []
        levels: list[str] = []
        poses: list[str] = []
        for target, local_nodes in visits:
            names, n_levels = self.locals[target].node_ids, self.locals[target].n_levels
            ids += [names[i] for i in local_nodes]
            levels += [names[i] for i in local_nodes if i < n_levels]
            poses += [names[i] for i in local_nodes if i >= n_levels]
        return ids, levels, poses


class HierarchicalPlanner:
    """Answers planning queries over a :class:`LayeredSemanticGraph`.

    Search structures are cached and rebuilt only when the graph's revision changes; an
    inspected target's local graph never changes, so its index is built once.
    """

    def __init__(self, graph: LayeredSemanticGraph) -> None:
        self.graph = graph
        self._network_cache: _Network | None = None
        self._local_cache: dict[str, _LocalIndex] = {}
        warm_up()

    # ------------------------------------------------------------------ public API
    def query(self, text: str, start: ArrayLike | None = None) -> RoutePlan:
        """Answer an operator query such as ``"Visit hood-1 in Level-0 of car-1"``."""
        parsed = parse_query(text)
        goal_id = resolve_query(self.graph, parsed)
        return self.plan(goal_id, start, verb=parsed.verb, query=str(parsed))

    def plan(
        self,
        goal_id: str,
        start: ArrayLike | None = None,
        *,
        verb: Verb = Verb.VISIT,
        query: Query | str | None = None,
    ) -> RoutePlan:
        """Plan from ``start`` (default: the robot's position) to the node ``goal_id``.

        The reported timing excludes rebuilding the search index after the graph changed
        (done once per change, e.g. once per inspected target, and shared by later queries).
        """
        network = self._network()
        t0 = time.perf_counter()
        origin = self.graph.robot.position if start is None else as_point(start, "start")
        goal_node = self.graph.node(goal_id)
        goal_target, goal_local, terminal = self._goal(network, goal_node)
        t1 = time.perf_counter()
        start_target, start_local, distance = self._localise(network, origin)
        t2 = time.perf_counter()
        searches = _Searches()
        if start_target == goal_target:
            segments = [searches.local(network.locals[start_target], start_local, goal_local)]
            hops: list[int] = [start_target]
        else:
            first = searches.local(network.locals[start_target], start_local, 0)
            hops = searches.targets(network, start_target, goal_target)
            last = searches.local(network.locals[goal_target], 0, goal_local)
            segments = [first, last]
        t3 = time.perf_counter()
        return self._assemble(
            network,
            origin=origin,
            goal_node=goal_node,
            terminal=terminal,
            hops=hops,
            segments=segments,
            searches=searches,
            localisation=self._localisation(network, start_target, start_local, distance),
            timing=(t0, t1, t2, t3),
            verb=verb,
            query=None if query is None else str(query),
        )

    def localise(self, position: ArrayLike) -> Localisation:
        """The robot's place in the layers for a metric position."""
        network = self._network()
        target, local, distance = self._localise(network, as_point(position, "position"))
        return self._localisation(network, target, local, distance)

    def nearest_entry(self, position: ArrayLike) -> str:
        """Id of the traversable node nearest to ``position`` (for legs into unknown space)."""
        network = self._network()
        target, local, _ = self._localise(network, as_point(position, "position"))
        return network.locals[target].node_ids[local]

    # ------------------------------------------------------------------ search structures
    def _network(self) -> _Network:
        cached = self._network_cache
        if cached is not None and cached.revision == self.graph.revision:
            return cached
        inspected = self.graph.targets(TargetStatus.INSPECTED)
        routable = [t for t in inspected if t.levels]
        target_index = {t.id: i for i, t in enumerate(routable)}
        locals_ = [self._local_index(t) for t in routable]
        coords = np.array([LayeredSemanticGraph.entry_level(t).position for t in routable])
        pairs, weights, edges = [], [], {}
        for edge in self.graph.target_graph.edges.values():
            if edge.kind is EdgeKind.SPATIAL and edge.u in target_index and edge.v in target_index:
                i, j = target_index[edge.u], target_index[edge.v]
                pairs.append((i, j))
                weights.append(edge.weight)
                edges[(i, j)] = edges[(j, i)] = edge
        owner = np.concatenate(
            [np.full(len(loc.node_ids), i, dtype=np.int64) for i, loc in enumerate(locals_)]
            or [np.empty(0, np.int64)]
        )
        local_of = np.concatenate(
            [np.arange(len(loc.node_ids), dtype=np.int64) for loc in locals_]
            or [np.empty(0, np.int64)]
        )
        points = [loc.csr.coords for loc in locals_]
        self._network_cache = _Network(
            revision=self.graph.revision,
            target_ids=[t.id for t in routable],
            target_index=target_index,
            target_csr=CsrGraph.from_edges(coords.reshape(-1, 3), pairs, weights),
            target_edges=edges,
            locals=locals_,
            nearest=NearestIndex.build(np.vstack(points)) if points else None,
            owner=owner,
            local_of=local_of,
        )
        return self._network_cache

    def _local_index(self, target: TargetNode) -> _LocalIndex:
        cached = self._local_cache.get(target.id)
        if cached is not None:
            return cached
        levels = target.levels
        nodes: list[LevelNode | PoseNode] = [*levels, *(p for lv in levels for p in lv.poses)]
        index = {node.id: i for i, node in enumerate(nodes)}
        graphs = [target.level_graph, *(lv.pose_graph for lv in levels)]
        spatial = [
            e
            for g in graphs
            if g is not None
            for e in g.edges.values()
            if e.kind is EdgeKind.SPATIAL
        ]
        csr = CsrGraph.from_edges(
            [node.position for node in nodes],
            [(index[e.u], index[e.v]) for e in spatial],
            [e.weight for e in spatial],
        )
        vias: dict[tuple[int, int], NDArray[np.float64]] = {}
        for e in spatial:
            if e.via is not None:
                vias[(index[e.u], index[e.v])] = e.via
                vias[(index[e.v], index[e.u])] = e.via[::-1]
        local = _LocalIndex([node.id for node in nodes], index, csr, len(levels), vias)
        self._local_cache[target.id] = local
        return local

    # ------------------------------------------------------------------ steps
    def _goal(self, network: _Network, node: Node) -> tuple[int, int, str | None]:
        """(target index, local index, terminal feature id) of a goal node."""
        terminal = None
        if isinstance(node, FeatureNode):
            terminal = node.id
            node = self.graph.node(node.pose_id)
        if isinstance(node, TargetNode):
            if node.id not in network.target_index:
                raise PlanningError(
                    f"{node.id} is {node.status.value} but has no inspected levels: "
                    "the graph holds no route into it"
                )
            return network.target_index[node.id], 0, terminal
        if isinstance(node, PoseNode):
            target_id = self.graph.node(node.level_id).target_id  # type: ignore[union-attr]
        elif isinstance(node, LevelNode):
            target_id = node.target_id
        else:
            raise PlanningError(f"{node.id} is not a place the robot can go to")
        if target_id not in network.target_index:
            raise PlanningError(
                f"{node.id} belongs to {target_id}, whose inspection is not finished"
            )
        target = network.target_index[target_id]
        return target, network.locals[target].index[node.id], terminal

    def _localise(self, network: _Network, position: NDArray[np.float64]) -> tuple[int, int, float]:
        if network.nearest is None:
            raise PlanningError("the graph has no inspected targets to plan over")
        row, distance = network.nearest.nearest(position)
        return int(network.owner[row]), int(network.local_of[row]), float(distance)

    def _localisation(
        self, network: _Network, target: int, local: int, distance: float
    ) -> Localisation:
        node_id = network.locals[target].node_ids[local]
        node = self.graph.node(node_id)
        if isinstance(node, PoseNode):
            return Localisation(
                network.target_ids[target], node.level_id, node.id, node_id, distance
            )
        return Localisation(network.target_ids[target], node_id, None, node_id, distance)

    def _assemble(
        self,
        network: _Network,
        *,
        origin: NDArray[np.float64],
        goal_node: Node,
        terminal: str | None,
        hops: list[int],
        segments: list[NDArray[np.int64]],
        searches: _Searches,
        localisation: Localisation,
        timing: tuple[float, float, float, float],
        verb: Verb,
        query: str | None,
    ) -> RoutePlan:
        waypoints, target_length = network.route_points(origin, hops, segments)
        ids, levels, poses = network.route_nodes(hops, segments)
        t0, t1, t2, _ = timing
        return RoutePlan(
            goal_id=goal_node.id,
            terminal_id=terminal,
            start=origin,
            localisation=localisation,
            target_route=tuple(network.target_ids[h] for h in hops),
            node_path=tuple(ids),
            waypoints=waypoints,
            cost=searches.cost,
            target_layer_length=target_length,
            timing=PlanTiming(
                localise_s=t2 - t1,
                target_layer_s=searches.target_s,
                local_layers_s=searches.local_s,
                total_s=time.perf_counter() - t0,
            ),
            settled=searches.settled,
            final_yaw=self._final_yaw(goal_node, terminal, waypoints[-1], verb),
            query=query,
            level_route=tuple(levels),
            pose_route=tuple(poses),
        )

    def _final_yaw(
        self, goal: Node, terminal: str | None, end: NDArray[np.float64], verb: Verb
    ) -> float | None:
        """Face the observed feature (or, for Observe, the target); hold a pose's heading."""
        focus: NDArray[np.float64] | None = None
        if terminal is not None:
            focus = self.graph.node(terminal).position
        elif isinstance(goal, PoseNode):
            return yaw_from_quat(goal.orientation)
        elif verb is Verb.OBSERVE and isinstance(goal, TargetNode | LevelNode):
            target = goal if isinstance(goal, TargetNode) else self.graph.node(goal.target_id)
            focus = target.position
        if focus is None:
            return None
        dx, dy = float(focus[0] - end[0]), float(focus[1] - end[1])
        # Plain floats: numpy's allclose costs more than the searches of a query.
        return None if math.hypot(dx, dy) <= 1e-8 else math.atan2(dy, dx)


class _Searches:
    """Runs and times the searches of one query."""

    def __init__(self) -> None:
        self.cost = 0.0
        self.settled = 0
        self.target_s = 0.0
        self.local_s = 0.0

    def local(self, local: _LocalIndex, source: int, target: int) -> NDArray[np.int64]:
        t0 = time.perf_counter()
        cost, path, settled = shortest_path(local.csr, source, target)
        self.local_s += time.perf_counter() - t0
        if not path.size:
            raise PlanningError(
                f"{local.node_ids[target]} is not connected to {local.node_ids[source]}"
            )
        self.cost += cost
        self.settled += settled
        return path

    def targets(self, network: _Network, source: int, target: int) -> list[int]:
        t0 = time.perf_counter()
        cost, path, settled = shortest_path(network.target_csr, source, target)
        self.target_s += time.perf_counter() - t0
        if not path.size:
            a, b = network.target_ids[source], network.target_ids[target]
            raise PlanningError(
                f"no route from {a} to {b}: they are not connected in the Target layer"
            )
        self.cost += cost
        self.settled += settled
        return [int(i) for i in path]
