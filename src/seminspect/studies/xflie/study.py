"""Hierarchical versus volumetric planning on real missions (000 Sec VII-C/D, Tables 5 and 6):
the Table 5 comparison on a mission's final graph, and the whole study run end to end.

**Table 5 analogue.** A city mission's final 3DLSG is queried as an operator would query it
("Visit front-bumper-1 in Level-0 of truck-4") from the robot's final pose. Each query is answered
by the hierarchical planner and, from the same start to the same end, by the volumetric baseline
on the world's voxel map at 0.4, 0.5 and 0.7 m (ground band, robot radius; the map built once,
outside the timed query). Every path is checked segment by segment against the true world, and
the hierarchical path is also refined: consecutive waypoints are shortcut where the straight
segment is free in the robot's own final map (``map.npz`` of the run).

**Table 6 analogue** (:mod:`.missions`): the same missions with the volumetric planner and as
frontier exploration, planning time charged, compared on CPU load, planning load, inspection
coverage and localisation RMSE under the same time budget. **Fig 13** (:mod:`.scaling`):
synthetic cities of growing size.

Mission runs are kept in a runs directory and reused when they hold a completed run of the same
configuration, so the study can be repeated quickly.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.io import load_graph
from seminspect.graphs.lsg.model import EdgeKind
from seminspect.mapping.voxel import VoxelMap, load_map
from seminspect.missions.xflie import PLANNING_MARGIN
from seminspect.missions.xflie.config import MissionConfig
from seminspect.missions.xflie.layout import MAP_FILE, load_run_world
from seminspect.planning.gridmap import CostGrid, CostModel
from seminspect.planning.hierarchical import HierarchicalPlanner
from seminspect.planning.smoothing import refine_path
from seminspect.planning.volumetric import VolumetricPlanner
from seminspect.runs.directory import read_run_config
from seminspect.runs.trajectory import load_trajectory
from seminspect.studies.xflie.comparison import (
    HierarchicalTiming,
    VolumetricResult,
    fine_segment_validity,
    segment_validity,
    time_hierarchical,
    time_volumetric,
)
from seminspect.studies.xflie.missions import (
    TABLE6_SEEDS,
    MissionOutcome,
    StudyProgress,
    ensure_run,
    mission_progress,
    mission_study,
    study_config,
)
from seminspect.studies.xflie.queries import reachable_targets, select_queries
from seminspect.studies.xflie.scaling import SCALING_SIZES, ScalingPoint, scaling_study
from seminspect.worlds import World

#: Volumetric map resolutions: 000 Table 5's 0.5 and 0.7 m, and Table 6's 0.4 m [m].
RESOLUTIONS = (0.4, 0.5, 0.7)
#: Volumes the volumetric baseline may search: ``ground``, the robot's own height band
#: (8-connected, what a ground robot can drive); ``full``, every height of the map (26-connected,
#: as 000's D*+ searched the OctoMap of its simulated aerial robot).
VOLUMES = ("ground", "full")


@dataclass(frozen=True)
class PathCheck:
    """Segments of a path that a robot of the study's radius sweeps without touching the world."""

    valid: int
    segments: int

    @classmethod
    def of(
        cls, world: World, waypoints: ArrayLike, radius: float, volume: str = "ground"
    ) -> PathCheck:
        """Check a path driven on the ground, or flown through the whole ``volume``."""
        if volume == "ground":
            free = segment_validity(world, waypoints, radius, "ground")
        else:
            free = fine_segment_validity(world, waypoints, radius)
        return cls(int(free.sum()), len(free))

    @property
    def all_valid(self) -> bool:
        return self.valid == self.segments


@dataclass(frozen=True)
class QueryComparison:
    """One query answered by both planners (seconds, metres)."""

    query: str
    goal: str
    straight_m: float
    hp: HierarchicalTiming
    hp_target_layer_m: float
    hp_length_m: float
    hp_check: PathCheck
    refined_length_m: float
    refine_s: float
    refined_check: PathCheck
    vp: tuple[VolumetricResult, ...]
    vp_checks: tuple[PathCheck, ...]

    def volumetric(self, resolution: float) -> VolumetricResult:
        return self.vp[self._vp_index(resolution)]

    def vp_check(self, resolution: float) -> PathCheck:
        """The world check of the volumetric path at ``resolution``."""
        return self.vp_checks[self._vp_index(resolution)]

    def _vp_index(self, resolution: float) -> int:
        for index, result in enumerate(self.vp):
            if math.isclose(result.resolution, resolution):
                return index
        raise InvalidInputError(f"no volumetric result at {resolution} m")

    def time_ratio(self, resolution: float, basis: str = "search") -> float:
        """Volumetric time over hierarchical time: ``search`` (the paper's per-layer searches),
        ``plan`` (the planner's total), ``query`` (end to end) or ``refined`` (end to end plus
        the refinement)."""
        hp = {
            "search": self.hp.search_s,
            "plan": self.hp.plan_s,
            "query": self.hp.query_s,
            "refined": self.hp.query_s + self.refine_s,
        }[basis]
        return self.volumetric(resolution).time_s / hp

    def length_ratio(self, resolution: float, refined: bool = False) -> float:
        """Hierarchical path length over the volumetric one."""
        hp = self.refined_length_m if refined else self.hp_length_m
        return hp / self.volumetric(resolution).length


@dataclass(frozen=True)
class RunComparison:
    """Every query of one mission run."""

    scenario: str | None
    run_dir: Path
    start: NDArray[np.float64]
    graph_nodes: int
    inspected_targets: int
    map_build_s: dict[float, float]
    #: Segments of every spatial edge of the graph that are free in the world.
    edge_check: PathCheck
    #: Calls per query whose median is reported: hierarchical (and refinement), volumetric.
    repeats: int
    vp_repeats: int
    queries: list[QueryComparison] = field(default_factory=list)
    #: The volume the volumetric baseline searched (one of :data:`VOLUMES`).
    volume: str = "ground"


@dataclass
class _Setting:
    """What a run's comparison needs, loaded once."""

    world: World
    graph: LayeredSemanticGraph
    start: NDArray[np.float64]
    radius: float
    #: The robot's final map as its planners see it (clearance with the mission's margin).
    robot_grid: CostGrid
    planners: dict[float, VolumetricPlanner]
    #: The volume the volumetric baseline searches (one of :data:`VOLUMES`).
    volume: str


def graph_edge_check(graph: LayeredSemanticGraph, world: World, radius: float) -> PathCheck:
    """Segments of the polylines of every spatial edge of the graph, checked in the world."""
    checks = [
        PathCheck.of(world, graph.edge_path(e), radius)
        for e in graph.edges()
        if e.kind is EdgeKind.SPATIAL
    ]
    return PathCheck(sum(c.valid for c in checks), sum(c.segments for c in checks))


def final_pose(run_dir: Path) -> NDArray[np.float64]:
    """Where the robot believed it stood at the end of the run (odometry)."""
    trajectory = load_trajectory(run_dir)
    if not len(trajectory):
        raise FileFormatError(f"{run_dir / 'trajectory.csv'}: no trajectory to start from")
    return trajectory[-1, 5:8].copy()


def _setting(
    run_dir: Path, resolutions: Sequence[float], volume: str
) -> tuple[_Setting, dict[float, float]]:
    config = read_run_config(run_dir)
    world = load_run_world(run_dir)
    radius = float(config["robot"]["radius"])
    band = MissionConfig.model_validate(config).robot.planning_band()
    robot_map: VoxelMap = load_map(run_dir / MAP_FILE)
    own = CostModel(radius + PLANNING_MARGIN, risk_radius=0.0, unknown_cost=None)
    start = final_pose(run_dir)
    planners, build = {}, {}
    for resolution in resolutions:
        if volume == "ground":
            known = VoxelMap.from_world(world, resolution)
            vp_band: tuple[float, float] | None = above_ground(band, known)
        else:
            known = VoxelMap.from_world(world, resolution, flight_box(world, resolution, start[2]))
            vp_band = None
        planner = VolumetricPlanner(known, CostModel(radius), band=vp_band)
        planners[resolution], build[resolution] = planner, planner.build_time
    setting = _Setting(
        world=world,
        graph=load_graph(run_dir / "graph.json"),
        start=start,
        radius=radius,
        robot_grid=CostGrid.build(robot_map, own, band),
        planners=planners,
        volume=volume,
    )
    return setting, build


def flight_box(world: World, resolution: float, floor: float) -> NDArray[np.float64]:
    """The world's box from the height ``floor`` up, its bottom layer of cells centred there.

    The full-volume baseline flies no lower than the robot's own centre: one layer lower, a
    body of the robot's radius would graze the ground in a coarse map.
    """
    box = np.array(world.bounds, dtype=np.float64)
    box[0, 2] = floor - 0.5 * resolution
    return box


def above_ground(band: tuple[float, float], known: VoxelMap) -> tuple[float, float]:
    """The ground band raised above the map's bottom layer of cells, which holds the ground
    (and, at 0.7 m, everything up to 0.35 m) in a map built by ``VoxelMap.from_world``."""
    return (max(band[0], float(known.origin[2]) + known.resolution + 1e-6), band[1])


def compare_run(
    run_dir: str | Path,
    *,
    count: int = 9,
    repeats: int = 200,
    vp_repeats: int = 3,
    resolutions: Sequence[float] = RESOLUTIONS,
    volume: str = "ground",
    progress: Callable[[str], None] | None = None,
) -> RunComparison:
    """Select ``count`` queries on a run's final graph and answer each with both planners,
    the volumetric one searching ``volume`` (one of :data:`VOLUMES`)."""
    _check_volume(volume)
    root = Path(run_dir)
    setting, build = _setting(root, resolutions, volume)
    planner = HierarchicalPlanner(setting.graph)
    refine_path(setting.graph.robot.position[None].repeat(2, 0), setting.robot_grid)  # warm up
    reachable = reachable_targets(planner, setting.start)
    comparisons = []
    for text in select_queries(setting.graph, setting.start, count, reachable):
        comparisons.append(_compare(setting, planner, text, repeats, vp_repeats))
        if progress is not None:
            progress(text)
    config = read_run_config(root)
    stats = setting.graph.population()
    return RunComparison(
        scenario=config.get("scenario"),
        run_dir=root,
        start=setting.start,
        graph_nodes=stats.unified.nodes,
        inspected_targets=stats.targets_inspected,
        map_build_s=build,
        edge_check=graph_edge_check(setting.graph, setting.world, setting.radius),
        repeats=repeats,
        vp_repeats=vp_repeats,
        queries=comparisons,
        volume=volume,
    )


def _compare(
    setting: _Setting, planner: HierarchicalPlanner, text: str, repeats: int, vp_repeats: int
) -> QueryComparison:
    start = setting.start
    route, timing = time_hierarchical(lambda: planner.query(text, start), repeats)
    refinements = [refine_path(route.waypoints, setting.robot_grid) for _ in range(repeats)]
    refined = refinements[-1]
    end = route.waypoints[-1]
    answers = tuple(time_volumetric(vp, start, end, vp_repeats) for vp in setting.planners.values())
    return QueryComparison(
        query=text,
        goal=route.goal_id,
        straight_m=float(np.linalg.norm((end - start)[:2])),
        hp=timing,
        hp_target_layer_m=route.target_layer_length,
        hp_length_m=route.length,
        hp_check=PathCheck.of(setting.world, route.waypoints, setting.radius),
        refined_length_m=refined.refined_length,
        refine_s=statistics.median(r.refine_time for r in refinements),
        refined_check=PathCheck.of(setting.world, refined.waypoints, setting.radius),
        vp=answers,
        vp_checks=tuple(
            PathCheck.of(setting.world, a.waypoints, setting.radius, setting.volume)
            for a in answers
        ),
    )


@dataclass
class PlanningStudy:
    """Everything ``seminspect bench planning`` measures."""

    table5: list[RunComparison]
    scaling: list[ScalingPoint]
    table6: list[MissionOutcome]


def run_study(
    scenarios: Sequence[str],
    runs_dir: str | Path,
    *,
    queries: int = 9,
    sizes: Sequence[int] = SCALING_SIZES,
    missions: bool = True,
    volume: str = "ground",
    progress: StudyProgress | None = None,
    seeds: Sequence[int] = TABLE6_SEEDS,
) -> PlanningStudy:
    """The Table 5 comparison on each scenario's mission (the volumetric baseline searching
    ``volume``), the scaling study over ``sizes`` (none when empty) and, with ``missions``, the
    Table 6 mission comparison over ``seeds``."""
    _check_volume(volume)
    table5 = []
    for scenario in scenarios:
        label = f"Table 5 mission: {scenario}"
        run_dir = ensure_run(study_config(scenario), runs_dir, mission_progress(progress, label))
        step = None if progress is None else (lambda text: progress(f"query: {text}", None))
        table5.append(compare_run(run_dir, count=queries, volume=volume, progress=step))
    scaling = (
        scaling_study(
            sizes, progress=None if progress is None else lambda n: progress(f"scaling: {n}", None)
        )
        if sizes
        else []
    )
    table6 = mission_study(scenarios, runs_dir, progress, seeds) if missions else []
    return PlanningStudy(table5, scaling, table6)


def _check_volume(volume: str) -> None:
    if volume not in VOLUMES:
        raise InvalidInputError(f"unknown volume {volume!r}; choose from {', '.join(VOLUMES)}")
