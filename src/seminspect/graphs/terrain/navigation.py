"""The place layer as a navigation graph: routes restricted to chosen terrain types."""

from __future__ import annotations

from collections.abc import Collection

import networkx as nx
import numpy as np
from numpy.typing import ArrayLike

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.core.names import unknown_name
from seminspect.geometry.transforms import as_point
from seminspect.graphs.terrain.scene_graph import TerrainSceneGraph

_NAVIGABLE = ("gvd", "traversable")


def _allowed(scene: TerrainSceneGraph, terrains: Collection[str] | None) -> set[str]:
    if terrains is None:
        return set(scene.prompts.terrain)
    chosen = set(terrains)
    for terrain in chosen:
        if terrain not in scene.prompts.terrain:
            raise unknown_name("terrain", terrain, scene.prompts.terrain)
    if not chosen:
        raise InvalidInputError("choose at least one terrain type to travel on")
    return chosen


def place_graph(scene: TerrainSceneGraph, terrains: Collection[str] | None = None) -> nx.Graph:
    """The places on the chosen terrains and the links between them, weighted by ``length``."""
    allowed = _allowed(scene, terrains)
    keep = [
        node
        for node, data in scene.graph.nodes(data=True)
        if data["kind"] == "place" and data["terrain"] in allowed
    ]
    graph = nx.Graph()
    graph.add_nodes_from(keep)
    for a, b, data in scene.graph.subgraph(keep).edges(data=True):
        if data["kind"] in _NAVIGABLE:
            graph.add_edge(a, b, length=data["length"])
    return graph


def shortest_route(
    scene: TerrainSceneGraph, start: str, goal: str, terrains: Collection[str] | None = None
) -> tuple[list[str], float]:
    """Shortest chain of places from ``start`` to ``goal`` over the chosen terrains, and length."""
    for node in (start, goal):
        if node not in scene.graph:
            raise unknown_name("place", node, scene.nodes_of("place"))
        if scene.graph.nodes[node]["kind"] != "place":
            raise InvalidInputError(f"{node!r} is a {scene.graph.nodes[node]['kind']}, not a place")
    graph = place_graph(scene, terrains)
    for node in (start, goal):
        if node not in graph:
            terrain = scene.graph.nodes[node]["terrain"]
            raise PlanningError(f"{node!r} lies on {terrain!r}, which the route may not use")
    try:
        length, route = nx.single_source_dijkstra(graph, start, goal, weight="length")
    except nx.NetworkXNoPath:
        raise PlanningError(f"no route from {start!r} to {goal!r} on the chosen terrain") from None
    return route, float(length)


def nearest_place(
    scene: TerrainSceneGraph, point: ArrayLike, terrains: Collection[str] | None = None
) -> str:
    """The place on the chosen terrains closest to a 3D point."""
    target = as_point(point, "query point")
    allowed = _allowed(scene, terrains)
    best, best_distance = None, np.inf
    for node, data in scene.graph.nodes(data=True):
        if data["kind"] == "place" and data["terrain"] in allowed:
            distance = float(np.linalg.norm(data["position"] - target))
            if distance < best_distance:
                best, best_distance = node, distance
    if best is None:
        raise PlanningError("the graph has no place on the chosen terrain")
    return best
