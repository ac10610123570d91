"""Terrain-aware, task-driven outdoor scene graphs (001 Sec III)."""

from seminspect.graphs.terrain.evaluate import match_boxes, score_places
from seminspect.graphs.terrain.io import load_terrain_graph, save_terrain_graph, write_graphml
from seminspect.graphs.terrain.navigation import nearest_place, shortest_route
from seminspect.graphs.terrain.params import TerrainGraphParams, make_terrain_params
from seminspect.graphs.terrain.prompting import TaskPrompts
from seminspect.graphs.terrain.scene_graph import (
    TerrainBuild,
    TerrainSceneGraph,
    build_terrain_graph,
)

__all__ = [
    "TaskPrompts",
    "TerrainBuild",
    "TerrainGraphParams",
    "TerrainSceneGraph",
    "build_terrain_graph",
    "load_terrain_graph",
    "make_terrain_params",
    "match_boxes",
    "nearest_place",
    "save_terrain_graph",
    "score_places",
    "shortest_route",
    "write_graphml",
]
