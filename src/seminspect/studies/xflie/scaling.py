"""Planning time as the site grows (000 Fig 13, and far beyond the paper's 20 vehicles).

Synthetic cities of ``n`` vehicles on a jittered grid (the area grows with ``n``) give two maps of
one layout: the fully inspected 3DLSG of :func:`~seminspect.graphs.lsg.synthetic.synthetic_graph`
and a voxel map with a box per vehicle at the same place. Both planners answer the same random
start/goal pairs: the hierarchical planner goes from a point near a random view pose to a random
feature; the volumetric baseline (ground band, built once per city) goes from the same start to
the pose the hierarchical path ends at.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.core.rng import make_rng
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import FeatureNode
from seminspect.graphs.lsg.synthetic import VEHICLE_SIZE, synthetic_graph, synthetic_layout
from seminspect.mapping.voxel import VoxelMap
from seminspect.planning.gridmap import CostModel
from seminspect.planning.hierarchical import HierarchicalPlanner
from seminspect.planning.routes import DEFAULT_GROUND_BAND
from seminspect.planning.volumetric import VolumetricPlanner
from seminspect.studies.xflie.comparison import time_hierarchical, time_volumetric

#: City sizes (vehicles) of the default study: the paper's 20 up to a hundred times more.
SCALING_SIZES = (20, 50, 100, 200, 500, 1000, 2000)
#: Height of the box city's map [m] (the trucks are 3.2 m tall).
CITY_HEIGHT = 4.0
#: Free margin around the outermost vehicles [m].
CITY_MARGIN = 18.0


@dataclass(frozen=True)
class ScalingPoint:
    """Both planners on one synthetic city; times are medians (p95) over its queries."""

    targets: int
    graph_nodes: int
    traversable_nodes: int
    map_cells: int
    map_volume_m3: float
    queries: int
    hp_search_s: float
    hp_search_p95_s: float
    hp_plan_s: float
    hp_plan_p95_s: float
    hp_settled: float
    vp_s: float
    vp_p95_s: float
    vp_expansions: float
    vp_failures: int
    #: Medians over queries of volumetric time / hierarchical time.
    ratio_search: float
    ratio_plan: float


def box_city(
    n_targets: int, *, seed: int = 0, resolution: float = 0.5, spacing: float = 18.0
) -> VoxelMap:
    """A known voxel map with one box per vehicle of ``synthetic_graph(n_targets, seed=seed)``."""
    centres, labels = synthetic_layout(n_targets, seed=seed, spacing=spacing)
    half = np.array([VEHICLE_SIZE[label] for label in labels])
    lower = np.column_stack([centres[:, :2] - half[:, :2], np.zeros(len(centres))])
    upper = np.column_stack([centres[:, :2] + half[:, :2], half[:, 2]])
    extent = [*(upper[:, :2].max(axis=0) + CITY_MARGIN), CITY_HEIGHT]
    return VoxelMap.from_boxes([0.0, 0.0, 0.0], extent, resolution, np.stack([lower, upper], 1))


def scaling_point(
    n_targets: int,
    *,
    queries: int = 20,
    repeats: int = 20,
    seed: int = 0,
    resolution: float = 0.5,
    robot_radius: float = 0.4,
    band: tuple[float, float] = DEFAULT_GROUND_BAND,
) -> ScalingPoint:
    """Build one city's graph and map, then time ``queries`` random queries on both."""
    if not (isinstance(queries, int) and queries >= 1):
        raise InvalidInputError(f"queries must be a positive integer, got {queries!r}")
    graph = synthetic_graph(n_targets, seed=seed)
    hierarchical = HierarchicalPlanner(graph)
    voxel_map = box_city(n_targets, seed=seed, resolution=resolution)
    volumetric = VolumetricPlanner(voxel_map, CostModel(robot_radius), band=band)
    search, plan_s, settled, vp, expansions, ratio_search, ratio_plan = ([] for _ in range(7))
    failures = 0
    for start, goal in random_queries(graph, queries, seed):
        route, timing = time_hierarchical(partial(hierarchical.plan, goal, start), repeats)
        answer = time_volumetric(volumetric, start, route.waypoints[-1], repeats=1)
        search.append(timing.search_s)
        plan_s.append(timing.plan_s)
        settled.append(route.settled)
        if answer.error is not None:
            failures += 1
            continue
        vp.append(answer.time_s)
        expansions.append(answer.expansions)
        ratio_search.append(answer.time_s / timing.search_s)
        ratio_plan.append(answer.time_s / timing.plan_s)
    stats = graph.population()
    return ScalingPoint(
        targets=n_targets,
        graph_nodes=stats.unified.nodes,
        traversable_nodes=sum(len(lv.poses) + 1 for t in graph.targets() for lv in t.levels),
        map_cells=math.prod(volumetric.grid.shape),
        map_volume_m3=float(np.prod(voxel_map.upper - voxel_map.origin)),
        queries=queries,
        hp_search_s=statistics.median(search),
        hp_search_p95_s=_p95(search),
        hp_plan_s=statistics.median(plan_s),
        hp_plan_p95_s=_p95(plan_s),
        hp_settled=statistics.median(settled),
        vp_s=_median(vp),
        vp_p95_s=_p95(vp),
        vp_expansions=_median(expansions),
        vp_failures=failures,
        ratio_search=_median(ratio_search),
        ratio_plan=_median(ratio_plan),
    )


def scaling_study(
    sizes: Sequence[int] = SCALING_SIZES,
    *,
    progress: Callable[[int], None] | None = None,
    **options: float | int,
) -> list[ScalingPoint]:
    """:func:`scaling_point` for every size (``progress`` is called with each finished size)."""
    if not sizes or any(not (isinstance(n, int) and n >= 2) for n in sizes):
        raise InvalidInputError(f"city sizes must be integers >= 2, got {list(sizes)!r}")
    points = []
    for n in sizes:
        points.append(scaling_point(n, **options))  # type: ignore[arg-type]
        if progress is not None:
            progress(n)
    return points


def growth_exponent(sizes: ArrayLike, times: ArrayLike) -> float:
    """Slope of ``log(time)`` against ``log(size)`` (least squares): below 1 is sub-linear."""
    x, y = np.log(np.asarray(sizes, dtype=float)), np.log(np.asarray(times, dtype=float))
    if len(x) < 2 or not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise InvalidInputError("growth needs two or more positive, finite sizes and times")
    return float(np.polyfit(x, y, 1)[0])


def random_queries(
    graph: LayeredSemanticGraph, count: int, seed: int
) -> list[tuple[NDArray[np.float64], str]]:
    """``count`` (start, feature id) pairs: starts within about a metre of random view poses,
    goals at random features."""
    rng = make_rng(seed, "scaling", f"queries-{len(graph.targets())}")
    features = [n.id for n in graph.nodes() if isinstance(n, FeatureNode)]
    poses = [p.position for t in graph.targets() for lv in t.levels for p in lv.poses]
    picks = []
    for _ in range(count):
        anchor = poses[int(rng.integers(len(poses)))]
        start = anchor + rng.normal(0.0, 1.0, 3) * [1.0, 1.0, 0.0]
        picks.append((start, features[int(rng.integers(len(features)))]))
    return picks


def _median(values: Sequence[float]) -> float:
    return statistics.median(values) if values else math.nan


def _p95(values: Sequence[float]) -> float:
    return float(np.percentile(values, 95)) if values else math.nan
