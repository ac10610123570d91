"""The five-layer terrain-aware, task-driven scene graph of 001 Sec III-B, and how to build it.

Layers: 1 task-relevant points (kept as :class:`TaskPoints`, not as graph nodes), 2 objects,
3 terrain-aware places, 4 regions, 5 the map root. Layers 2-5 are nodes of one
:class:`networkx.Graph`; every node has ``layer`` and ``kind`` attributes and a ``position``.
Edge kinds: ``gvd`` (places of one terrain), ``traversable`` (places of touching terrains),
``object-place`` (an object and its closest place), ``region-member`` and ``map-region``
(hierarchy).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import networkx as nx
import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from seminspect.graphs.terrain.objects import ObjectCluster, extract_objects
from seminspect.graphs.terrain.params import ParamsChoice, TerrainGraphParams, params_for_cloud
from seminspect.graphs.terrain.places import PlaceLayer, build_places, warn_if_fragmented
from seminspect.graphs.terrain.prompting import TaskPoints, TaskPrompts, embed_prompts, task_points
from seminspect.graphs.terrain.regions import RegionClusters, agglomerate, task_distributions
from seminspect.mapping.semantic_cloud import SemanticCloud
from seminspect.perception.encoders import Calibration, TextEncoder, calibration_for

MAP_NODE = "map"
NULL_REGION = "none"


@dataclass
class TerrainSceneGraph:
    """Layers 2-5 as a graph, plus what produced them."""

    graph: nx.Graph
    prompts: TaskPrompts
    encoder: str
    calibration: Calibration
    params: TerrainGraphParams
    layer1_counts: dict[str, int]
    layer1: TaskPoints | None = None

    def nodes_of(self, kind: str) -> list[str]:
        """Node ids of one kind (``object``, ``place``, ``region``, ``map``) in insertion order."""
        return [n for n, data in self.graph.nodes(data=True) if data["kind"] == kind]

    def summary(self) -> dict[str, object]:
        places = self.nodes_of("place")
        per_terrain = {t: 0 for t in self.prompts.terrain}
        for node in places:
            per_terrain[self.graph.nodes[node]["terrain"]] += 1
        per_object = {o: 0 for o in self.prompts.objects}
        for node in self.nodes_of("object"):
            per_object[self.graph.nodes[node]["label"]] += 1
        return {
            "layer1_points": self.layer1_counts,
            "objects": per_object,
            "places": per_terrain,
            "place_edges": sum(
                1 for _, _, d in self.graph.edges(data=True) if d["kind"] in ("gvd", "traversable")
            ),
            "regions": len(self.nodes_of("region")),
        }


@dataclass
class TerrainBuild:
    """A built graph with the intermediate results the pictures and reports need."""

    scene: TerrainSceneGraph
    places: PlaceLayer
    objects: list[ObjectCluster]
    regions: RegionClusters
    cloud_classes: NDArray[np.int64]
    timings: dict[str, float] = field(default_factory=dict)
    choice: ParamsChoice | None = None


def _timed(timings: dict[str, float], name: str, on_stage: Callable[[str], None] | None):
    class _Stage:
        def __enter__(self) -> None:
            if on_stage:
                on_stage(name)
            self.start = time.perf_counter()

        def __exit__(self, *exc: object) -> None:
            timings[name] = time.perf_counter() - self.start

    return _Stage()


def _closest_places(objects: list[ObjectCluster], places: PlaceLayer) -> list[int | None]:
    """Index of the place closest to each object's centroid (001 Sec III-B.3, last sentence)."""
    if not places.places:
        return [None] * len(objects)
    tree = cKDTree(np.array([p.position for p in places.places]))
    return [int(tree.query(obj.centroid)[1]) for obj in objects]


def _primitive_similarity(
    layer: TaskPoints, places: PlaceLayer, objects: list[ObjectCluster]
) -> NDArray[np.float64]:
    """Mean similarity of each place's and each object's points to every prompt."""
    n_places = len(places.places)
    columns = layer.similarity.shape[1]
    owned = places.point_place >= 0
    counts = np.bincount(places.point_place[owned], minlength=n_places).astype(np.float64)
    place_sim = np.zeros((n_places, columns))
    for column in range(columns):
        place_sim[:, column] = np.bincount(
            places.point_place[owned], weights=layer.similarity[owned, column], minlength=n_places
        )
    for k, place in enumerate(places.places):
        if counts[k] == 0:  # cells filled by the closing: take the terrain's own mean
            rows = layer.of(place.terrain)
            place_sim[k] = layer.similarity[rows].mean(axis=0)
            counts[k] = 1.0
    place_sim /= np.maximum(counts, 1.0)[:, None]
    object_sim = np.array([layer.similarity[o.members].mean(axis=0) for o in objects])
    return np.vstack([place_sim, object_sim.reshape(len(objects), columns)])


def _assemble(
    prompts: TaskPrompts,
    places: PlaceLayer,
    objects: list[ObjectCluster],
    anchors: list[int | None],
    regions: RegionClusters,
) -> nx.Graph:
    graph = nx.Graph()
    for k, obj in enumerate(objects):
        graph.add_node(
            f"object-{k}",
            layer=2,
            kind="object",
            label=obj.label,
            position=obj.centroid,
            bbox_min=obj.bbox_min,
            bbox_max=obj.bbox_max,
            points=obj.n_points,
            score=obj.score,
        )
    for k, place in enumerate(places.places):
        graph.add_node(
            f"place-{k}",
            layer=3,
            kind="place",
            terrain=place.terrain,
            position=place.position,
            cell=list(place.cell),
            clearance=place.clearance,
            area=place.area,
        )
    for a, b, length, kind in places.edges:
        graph.add_edge(f"place-{a}", f"place-{b}", kind=kind, length=length)
    for k, anchor in enumerate(anchors):
        if anchor is not None:
            length = float(np.linalg.norm(objects[k].centroid - places.places[anchor].position))
            graph.add_edge(f"object-{k}", f"place-{anchor}", kind="object-place", length=length)
    _add_regions(graph, prompts, places, objects, regions)
    return graph


def _add_regions(
    graph: nx.Graph,
    prompts: TaskPrompts,
    places: PlaceLayer,
    objects: list[ObjectCluster],
    regions: RegionClusters,
) -> None:
    members = [f"place-{k}" for k in range(len(places.places))]
    members += [f"object-{k}" for k in range(len(objects))]
    names = (NULL_REGION, *prompts.all)
    region_positions = []
    for r, mix in enumerate(regions.distributions):
        inside = [members[i] for i in np.flatnonzero(regions.assignment == r)]
        position = np.mean([graph.nodes[m]["position"] for m in inside], axis=0)
        region_positions.append(position)
        graph.add_node(
            f"region-{r}",
            layer=4,
            kind="region",
            label=names[int(np.argmax(mix))],
            position=position,
            task_mix=mix,
            members=len(inside),
        )
        for member in inside:
            graph.add_edge(f"region-{r}", member, kind="region-member")
    root = np.mean(region_positions, axis=0) if region_positions else np.zeros(3)
    graph.add_node(MAP_NODE, layer=5, kind="map", label="map", position=root)
    for r in range(len(region_positions)):
        graph.add_edge(MAP_NODE, f"region-{r}", kind="map-region")


def build_terrain_graph(
    cloud: SemanticCloud,
    prompts: TaskPrompts,
    encoder: TextEncoder,
    *,
    params: TerrainGraphParams | None = None,
    calibration: Calibration | None = None,
    on_stage: Callable[[str], None] | None = None,
) -> TerrainBuild:
    """Phase 2 of 001 (Sec III-B): the task-driven graph of a metric-semantic cloud.

    ``calibration`` defaults to the thresholds registered for the cloud's encoder. Parameters
    that ``params`` does not set explicitly follow the terrain points' spacing
    (:func:`~seminspect.graphs.terrain.params.params_for_cloud`); the build's ``choice`` says
    what was derived.
    """
    calibration = calibration or calibration_for(cloud.encoder)
    timings: dict[str, float] = {}
    with _timed(timings, "prompts", on_stage):
        embeddings = embed_prompts(encoder, prompts.all, cloud.dim)
        layer, classes = task_points(cloud, prompts, embeddings, calibration)
        choice = params_for_cloud(layer.points[layer.classes < len(prompts.terrain)], params)
        params = choice.params
    with _timed(timings, "objects", on_stage):
        objects = extract_objects(
            layer, params.object_eps, params.object_min_points, params.object_voxel
        )
    with _timed(timings, "places", on_stage):
        places = build_places(layer, params)
        warn_if_fragmented(places, choice.spacing)
        anchors = _closest_places(objects, places)
    with _timed(timings, "regions", on_stage):
        py_x = task_distributions(
            _primitive_similarity(layer, places, objects),
            calibration.null_task,
            params.region_top_k,
        )
        n_places = len(places.places)
        links = [(a, b) for a, b, _, _ in places.edges]
        links += [(n_places + k, p) for k, p in enumerate(anchors) if p is not None]
        positions = [p.position for p in places.places] + [o.centroid for o in objects]
        regions = agglomerate(
            py_x,
            links,
            params.region_delta,
            np.array(positions).reshape(len(positions), 3),
            params.region_max_extent,
        )
    with _timed(timings, "assemble", on_stage):
        graph = _assemble(prompts, places, objects, anchors, regions)
    scene = TerrainSceneGraph(
        graph, prompts, cloud.encoder, calibration, params, layer.counts(), layer
    )
    return TerrainBuild(scene, places, objects, regions, classes, timings, choice)
