"""Hierarchical versus volumetric planning on real missions (000 Sec VII-C/D, Tables 5 and 6).

**Table 5 analogue.** A city mission's final 3DLSG is queried as an operator would query it
("Visit front-bumper-1 in Level-0 of truck-4") from the robot's final pose. Each query is answered
by the hierarchical planner and, from the same start to the same end, by the volumetric baseline
on the world's voxel map at 0.4, 0.5 and 0.7 m (ground band, robot radius; the map built once,
outside the timed query). Every path is checked segment by segment against the true world, and
the hierarchical path is also refined: consecutive waypoints are shortcut where the straight
segment is free in the robot's own final map (``map.npz`` of the run).

**Table 6 analogue.** The same missions are run with the volumetric planner between targets in
place of the hierarchical leg and local planner (the paper's "FLIE + 3DLSG + D*+"), and as pure
frontier exploration that never inspects (the role of the paper's GBPlanner2.0), with planning
wall time charged to the robot's clock in every mode, and compared on CPU load, planning load,
inspection coverage and localisation RMSE under the same time budget.

Mission runs are kept in a runs directory and reused when they hold a completed run of the same
configuration, so the study can be repeated quickly.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import FileFormatError, InvalidInputError, PlanningError
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.io import load_graph
from seminspect.graphs.lsg.model import EdgeKind, FeatureNode, TargetNode, TargetStatus
from seminspect.mapping.voxel import VoxelMap, load_map
from seminspect.missions.xflie import PLANNING_MARGIN, MissionProgress
from seminspect.missions.xflie.config import (
    CITY_BUDGETS,
    MissionConfig,
    inspects,
    make_config,
    resolve,
)
from seminspect.missions.xflie.run import run_name
from seminspect.missions.xflie.scoring import scored_matches
from seminspect.missions.xflie.sweep import run_or_reuse
from seminspect.planning.gridmap import CostGrid, CostModel
from seminspect.planning.hierarchical import HierarchicalPlanner
from seminspect.planning.smoothing import refine_path
from seminspect.planning.volumetric import VolumetricPlanner
from seminspect.runs.directory import (
    MAP_FILE,
    load_run_world,
    load_trajectory,
    read_run_config,
    read_run_metrics,
)
from seminspect.studies.xflie.comparison import (
    HierarchicalTiming,
    VolumetricResult,
    fine_segment_validity,
    segment_validity,
    time_hierarchical,
    time_volumetric,
)
from seminspect.studies.xflie.scaling import SCALING_SIZES, ScalingPoint, scaling_study
from seminspect.worlds import World

CITY_SCENARIOS = ("small", "medium", "large")
#: Volumetric map resolutions: 000 Table 5's 0.5 and 0.7 m, and Table 6's 0.4 m [m].
RESOLUTIONS = (0.4, 0.5, 0.7)
#: Volumes the volumetric baseline may search: ``ground``, the robot's own height band
#: (8-connected, what a ground robot can drive); ``full``, every height of the map (26-connected,
#: as 000's D*+ searched the OctoMap of its simulated aerial robot).
VOLUMES = ("ground", "full")
#: Parts the paper's Table 5 queries name; a target's query asks for the first one it has.
PREFERRED_FEATURES = ("front-bumper", "back-left-door", "front-glass", "trunk", "front-right-door")
#: Seeds of the Table 6 missions: the paper gives one figure per cell; three seeds show the spread.
TABLE6_SEEDS = (0, 1, 2)
#: Planners of the Table 6 missions: xFLIE, the volumetric baseline, the frontier explorer.
TABLE6_PLANNERS = ("hierarchical", "volumetric", "frontier")


@dataclass(frozen=True)
class PaperQuery:
    """One row of 000 Table 5 (seconds and metres)."""

    query: str
    target_layer_s: float
    target_layer_m: float
    pose_layer_s: float
    pose_layer_m: float
    vp05_s: float
    vp05_m: float
    vp07_s: float
    vp07_m: float


#: 000 Table 5, by scenario (1: small, 2: medium, 3: large).
PAPER_TABLE5: dict[str, tuple[PaperQuery, ...]] = {
    "small": (
        PaperQuery("Visit front-bumper-1 in Level-0 of truck-4",
                   1.7e-5, 32.33, 1.1e-4, 49.92, 0.526, 45.420, 0.220, 48.600),
        PaperQuery("Visit back-left-door-1 in Level-0 of car-0",
                   2.2e-5, 48.44, 1.1e-4, 56.86, 0.632, 45.229, 0.250, 46.536),
        PaperQuery("Visit front-bumper-1 in Level-0 of car-1",
                   1.6e-5, 16.11, 5.8e-5, 19.74, 0.560, 16.020, 0.110, 17.180),
    ),
    "medium": (
        PaperQuery("Visit trunk-1 in Level-0 of truck-9",
                   4.0e-5, 49.80, 2.1e-4, 70.83, 1.085, 57.479, 0.431, 59.580),
        PaperQuery("Visit front-glass-1 in Level-0 of truck-6",
                   3.5e-5, 89.44, 3.2e-4, 105.86, 1.150, 76.000, 0.369, 77.179),
        PaperQuery("Visit front-bumper-1 in Level-0 of truck-2",
                   2.7e-5, 68.60, 2.2e-4, 66.53, 1.030, 53.414, 0.390, 53.815),
    ),
    "large": (
        PaperQuery("Visit front-bumper-1 in Level-0 of car-9",
                   7.74e-5, 85.16, 3.4e-4, 95.85, 1.7, 77.63, 0.75, 80.76),
        PaperQuery("Visit front-glass-1 in Level-1 of truck-16",
                   7.71e-5, 136.48, 5.4e-4, 145.50, 1.9, 102.15, 0.53, 103.40),
        PaperQuery("Visit front-right-door-1 in Level-0 of truck-18",
                   7.6e-5, 110.69, 4.1e-4, 119.52, 0.35, 73.08, 0.45, 74.19),
    ),
}  # fmt: skip

#: 000 Table 6: (computational load %, inspection coverage m^3, target localisation RMSE m);
#: the frontier explorer stands beside the paper's GBPlanner2.0 row.
PAPER_TABLE6: dict[str, dict[str, tuple[float, float, float]]] = {
    "small": {
        "volumetric": (103.57, 103.02, 0.19),
        "frontier": (87.63, 64.19, 0.66),
        "hierarchical": (42.68, 107.74, 0.17),
    },
    "medium": {
        "volumetric": (113.755, 298.94, 0.28),
        "frontier": (93.81, 215.22, 0.58),
        "hierarchical": (44.66, 331.40, 0.195),
    },
    "large": {
        "volumetric": (118.42, 506.84, 0.40),
        "frontier": (101.40, 372.48, 1.37),
        "hierarchical": (52.10, 573.40, 0.24),
    },
}


# ---------------------------------------------------------------------------- mission runs
def study_config(
    scenario: str, planner: str = "hierarchical", *, table6: bool = False, seed: int = 0
) -> MissionConfig:
    """The city mission of a scenario: default settings for Table 5; for Table 6 the paper's
    time budget (000 Sec VII-D: 700, 1400, 2800 s) with planning time charged."""
    if scenario not in CITY_SCENARIOS:
        raise InvalidInputError(
            f"unknown city scenario {scenario!r}; choose from {', '.join(CITY_SCENARIOS)}"
        )
    values: dict[str, Any] = {
        "world": "city",
        "scenario": scenario,
        "seed": seed,
        "planner": planner,
    }
    if table6:
        values |= {"charge_planning_time": True, "time_budget_s": CITY_BUDGETS[scenario]}
    return resolve(make_config(values))


def ensure_run(
    config: MissionConfig,
    runs_dir: str | Path,
    progress: Callable[[MissionProgress], None] | None = None,
) -> Path:
    """The run directory of ``config`` under ``runs_dir``: reused when it holds a completed run of
    the same configuration with its map, run (again) otherwise."""
    config = resolve(config)
    suffix = f"-{config.planner}" + ("-charged" if config.charge_planning_time else "")
    out = Path(runs_dir) / (run_name(config) + suffix)
    run_or_reuse(config, out, progress)
    return out


# ---------------------------------------------------------------------------- queries
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


# ---------------------------------------------------------------------------- comparison
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


# ---------------------------------------------------------------------------- Table 6
@dataclass(frozen=True)
class MissionOutcome:
    """The Table 6 columns of one mission run, and what explains them."""

    scenario: str
    planner: str
    run_dir: Path
    cpu_load_pct: float
    planning_load_pct: float | None
    planning_wall_s: float
    bbox_volume_m3: float
    surface_coverage_pct: float | None
    rmse_m: float | None
    inspected: int
    true_targets: int
    sim_time_s: float
    wall_time_s: float
    route_plans: int
    seed: int = 0
    #: Horizontal localisation error of each target Table 6 scores (inspected; for the frontier
    #: explorer, every target found), by the true object's name [m].
    inspected_errors: dict[str, float] = field(default_factory=dict)
    #: Targets in the graph that match a true object, inspected or not.
    found: int = 0

    @classmethod
    def read(cls, run_dir: Path, scenario: str, planner: str) -> MissionOutcome:
        metrics = read_run_metrics(run_dir)
        t6, mission, targets = metrics.table6, metrics.mission, metrics.targets
        scored = scored_matches(targets.matches, inspects(planner))
        return cls(
            scenario=scenario,
            planner=planner,
            run_dir=run_dir,
            cpu_load_pct=t6.cpu_load_pct,
            planning_load_pct=t6.planning_load_pct,
            planning_wall_s=mission.planning_wall_s,
            bbox_volume_m3=t6.bbox_volume_m3,
            surface_coverage_pct=t6.surface_coverage_pct,
            rmse_m=t6.localisation_rmse_m,
            inspected=targets.inspected,
            true_targets=targets.true,
            sim_time_s=mission.sim_time_s,
            wall_time_s=mission.wall_time_s,
            route_plans=mission.local_plans,
            seed=metrics.world.seed,
            inspected_errors={m.truth: m.horizontal_error for m in scored},
            found=targets.matched,
        )


#: Called with a finished step's label (``mission`` None), or with a running mission's progress.
StudyProgress = Callable[[str, MissionProgress | None], None]


def mission_study(
    scenarios: Sequence[str],
    runs_dir: str | Path,
    progress: StudyProgress | None = None,
    seeds: Sequence[int] = TABLE6_SEEDS,
    planners: Sequence[str] = TABLE6_PLANNERS,
) -> list[MissionOutcome]:
    """Each scenario and seed with each planner, planning time charged to the robot (reusing
    runs). Every planner of a seed works in the same world: the same true targets."""
    outcomes = []
    for scenario in scenarios:
        for seed in seeds:
            for planner in planners:
                label = f"Table 6 mission: {scenario}, seed {seed}, {planner}"
                config = study_config(scenario, planner, table6=True, seed=seed)
                run_dir = ensure_run(config, runs_dir, _mission_progress(progress, label))
                outcomes.append(MissionOutcome.read(run_dir, scenario, planner))
                if progress is not None:
                    progress(label, None)
    return outcomes


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
        run_dir = ensure_run(study_config(scenario), runs_dir, _mission_progress(progress, label))
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


def _mission_progress(
    progress: StudyProgress | None, label: str
) -> Callable[[MissionProgress], None] | None:
    if progress is None:
        return None
    return lambda state: progress(label, state)
