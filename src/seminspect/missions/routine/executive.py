"""Routine inspection on an outdated map: the adaptive framework of 002, end to end.

:func:`~seminspect.missions.routine.prior.record_prior` drives a mapping traverse through the
historical world and returns ``M_H``. :class:`RoutineMission` then runs Algorithm 1 in the
current world, with the settings of :class:`~seminspect.missions.routine.config.RoutineConfig`:

1. ``GenerateGlobalViewPlan``: the Fig 3 view grid of every region on ``M_H``
   (:mod:`~seminspect.planning.global_views`), poses in collision repaired or dropped.
2. ``EvalInspectionTasks``: the next task ``R*`` is the one with the shortest traversable route
   over ``M_H`` from where the robot stands; unreachable tasks are skipped and reported.
3. ``NavigateToTask``: the ``M_H`` route is cut into segments and each segment's end is
   re-planned over ``M_C``, the map the robot builds now from its LiDAR and camera, so an
   obstruction that ``M_H`` does not know is driven around (segment ends inside it are skipped).
4. ``ComputeVisitingTour``: SA-TSP over the task's views (:mod:`~seminspect.planning.tour`),
   timed and compared with LKH when ``elkai`` is installed.
5. Adaptive local planning (:func:`~seminspect.planning.adaptive_cycle.plan_cycle`) once per tour
   pose: track ``Π_LVP``'s first pose when ``Γ_s > Γ_t`` (and adaptation is on), otherwise the
   global pose. Either way the tour pose counts as tracked (directly or through its
   approximation); the task is complete when every pose of ``Z*`` was tracked.

The robot is holonomic and aerial-capable, standing in for the paper's Spot with its camera at
each view's height; the camera is 002's (α 69.5°, β 45°, looking horizontally) and the LiDAR an
Ouster OS-0-like 32-beam, 90° unit. Sensors are ideal (no noise) and motion is tracked exactly
(the nMPC of 002 ref [14] is replaced by straight moves at the speed limit).
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import PlanningError, SeminspectError
from seminspect.core.rng import make_rng
from seminspect.geometry.depth_normals import viewpoint_utility
from seminspect.mapping.voxel import VoxelMap
from seminspect.missions.routine.config import RoutineConfig
from seminspect.missions.routine.measures import (
    RANGE_TOLERANCE_M,
    region_samples,
    seen_samples,
    view_distance,
)
from seminspect.missions.routine.prior import SENSE_EVERY_M, make_robot, sense
from seminspect.planning.adaptive_cycle import CycleDecision, plan_cycle
from seminspect.planning.global_views import (
    InspectionRegion,
    ViewPlan,
    global_view_plan,
    pose_is_clear,
)
from seminspect.planning.gridmap import CostModel
from seminspect.planning.routes import LocalPlanner
from seminspect.planning.tour import annealed_tour, reference_tour
from seminspect.sensors import Frame, render
from seminspect.worlds.routine_sites import SitePair

#: Extra clearance planned around the robot's radius on M_C [m]: covers the voxel size and the
#: conservative slack of the simulator's collision field.
PLANNING_MARGIN_M = 0.3


@dataclass(frozen=True)
class ViewSample:
    """One Algorithm 1 cycle and the view taken at its end (the time series of Figs 8-11)."""

    t: float
    task: str
    k: int
    x: float
    y: float
    z: float
    yaw: float
    gamma_s: float
    frechet_m: float
    adapted: bool
    rmse_before_m: float
    rmse_after_m: float
    utility: float
    view_distance_m: float
    cycle_ms: float


class RegionCoverage:
    """Which samples of a region's current surface some view has seen (ROI coverage)."""

    def __init__(self, samples: NDArray[np.float64]) -> None:
        self.samples = samples
        self.seen = np.zeros(len(samples), dtype=bool)

    def add(self, frame: Frame, d_view: float, tolerance: float) -> None:
        self.seen |= seen_samples(frame, self.samples, d_view - tolerance, d_view + tolerance)

    @property
    def percent(self) -> float | None:
        return 100.0 * float(self.seen.mean()) if len(self.seen) else None


@dataclass
class TaskRecord:
    """What happened to one inspection task."""

    name: str
    views_planned: int
    views_repaired: int
    views_dropped: int
    route_length_m: float | None = None
    views_tracked: int = 0
    completed: bool = False
    skipped: str = ""
    start_t: float | None = None
    end_t: float | None = None
    coverage_pct: float | None = None
    tour: dict[str, Any] = field(default_factory=dict)

    @property
    def time_s(self) -> float | None:
        if self.start_t is None or self.end_t is None:
            return None
        return self.end_t - self.start_t


@dataclass
class ActiveTask:
    """The task being worked on, for a watcher: its views (in visiting order once the tour is
    made), each one's outcome (True tracked, False unreachable, None not yet) and its
    region's coverage (None until the tour starts)."""

    index: int
    views: NDArray[np.float64]
    outcomes: list[bool | None]
    coverage: RegionCoverage | None = None


class RoutineWatch(Protocol):
    """Something that looks at a routine mission while it runs (the live view). It only reads,
    so a watched mission makes the same decisions as one nobody watches."""

    def step(self, frame: Frame | None) -> None:
        """The robot has sensed again: ``frame`` is the view just taken and recorded; None after
        a leg of driving or a view given up."""
        ...


class RoutineMission:
    """Algorithm 1 over a site pair with a prior map (module docstring).

    ``phase`` (``start``, ``navigate``, ``tour``, ``done``), ``active``, ``frame`` and ``watch``
    are there for a watcher (:mod:`~seminspect.missions.routine.live`); the mission never reads
    them.
    """

    def __init__(
        self,
        config: RoutineConfig,
        site: SitePair,
        prior: VoxelMap,
        regions: list[InspectionRegion],
        progress: Callable[[str, float], None] | None = None,
    ) -> None:
        self.config = config
        self.site = site
        self.world = site.current
        self.prior = prior
        self.regions = regions
        self.view = config.view_constraints()
        self.camera = config.camera()
        self.robot = make_robot(self.world, config)
        self.current_map = VoxelMap.empty(prior.origin, prior.upper, prior.resolution)
        self.rng = make_rng(config.seed, "missions", "routine", "tour")
        self.progress = progress
        self.samples: list[ViewSample] = []
        self.events: list[dict[str, Any]] = []
        self.planner = LocalPlanner(
            CostModel(config.robot_radius + PLANNING_MARGIN_M, unknown_cost=1.0), mode="aerial"
        )
        self.plans = [self._global_plan(region) for region in regions]
        self.tasks = [
            TaskRecord(p.region.name, len(p.positions), p.repaired, p.dropped) for p in self.plans
        ]
        self._cloud = np.empty((0, 3))
        self.phase = "start"
        self.active: ActiveTask | None = None
        self.frame: Frame | None = None  # the last view's camera frame
        self.watch: RoutineWatch | None = None

    # ----------------------------------------------------------------- set-up
    def _global_plan(self, region: InspectionRegion) -> ViewPlan:
        return global_view_plan(
            region,
            self.prior,
            self.view,
            robot_radius=self.config.robot_radius,
            height_limits=self.config.z_limits,
            viewer=self.world.start_position,
        )

    def _event(self, kind: str, **fields: Any) -> None:
        self.events.append({"t": round(self.robot.time, 3), "event": kind, **fields})

    # ----------------------------------------------------------------- the mission
    def execute(self) -> str:
        """Run every task; returns why the mission ended."""
        self._cloud = sense(self.robot, self.world, self.current_map)
        pending = [i for i, plan in enumerate(self.plans) if len(plan.positions)]
        for i, plan in enumerate(self.plans):
            if not len(plan.positions):
                self.tasks[i].skipped = "every view pose collides on M_H"
        while pending:
            selected = self._next_task(pending)
            if selected is None:
                for i in pending:
                    self.tasks[i].skipped = "no route over M_H"
                break
            chosen, route = selected
            pending.remove(chosen)
            self._run_task(chosen, route)
        self.phase = "done"
        done = sum(t.completed for t in self.tasks)
        return f"{done} of {len(self.tasks)} tasks completed"

    def _next_task(self, pending: list[int]) -> tuple[int, NDArray[np.float64]] | None:
        """EvalInspectionTasks: the task with the shortest route over M_H (and that route)."""
        best: tuple[float, int, NDArray] | None = None
        for i in pending:
            goal = self._nearest_view(self.plans[i])
            try:
                path = self.planner.plan(self.prior, self.robot.position, goal, goal_radius=0.3)
            except PlanningError as exc:
                self._event("task-unreachable", task=self.plans[i].region.name, reason=str(exc))
                continue
            self.tasks[i].route_length_m = path.length
            if best is None or path.length < best[0]:
                best = (path.length, i, path.waypoints)
        if best is None:
            return None
        self._event("task-selected", task=self.plans[best[1]].region.name, route_m=best[0])
        return best[1], best[2]

    def _nearest_view(self, plan: ViewPlan) -> NDArray[np.float64]:
        distances = np.linalg.norm(plan.positions - self.robot.position, axis=1)
        return plan.positions[int(np.argmin(distances))]

    def _run_task(self, index: int, route: NDArray[np.float64]) -> None:
        plan, record = self.plans[index], self.tasks[index]
        self.phase = "navigate"
        self.active = ActiveTask(index, plan.positions, [None] * len(plan.positions))
        self._navigate(route)
        record.start_t = self.robot.time
        order = self._visiting_tour(plan, record)
        positions, yaws = plan.positions[order], plan.yaws[order]
        coverage = RegionCoverage(region_samples(plan.region, self.world, plan.normal))
        self.phase = "tour"
        self.active = active = ActiveTask(index, positions, [None] * len(order), coverage)
        for k in range(len(order)):
            segment = slice(k, k + self.config.horizon)
            tracked = self._track(plan, positions[segment], yaws[segment], k, coverage)
            active.outcomes[k] = tracked
            self._show(self.frame if tracked else None)
            if tracked:
                record.views_tracked += 1
            if self.progress is not None:
                self.progress(plan.region.name, (k + 1) / len(order))
        record.end_t = self.robot.time
        record.completed = record.views_tracked == len(order)
        record.coverage_pct = coverage.percent
        self._event("task-done", task=record.name, tracked=record.views_tracked, views=len(order))

    def _visiting_tour(self, plan: ViewPlan, record: TaskRecord) -> NDArray[np.int64]:
        """ComputeVisitingTour: SA-TSP, timed, beside LKH's tour when elkai is installed."""
        started = time.perf_counter()
        tour = annealed_tour(self.robot.position, plan.positions, self.rng)
        record.tour = {"sa_length_m": tour.length, "sa_s": time.perf_counter() - started}
        try:
            started = time.perf_counter()
            reference = reference_tour(self.robot.position, plan.positions)
        except SeminspectError:
            return tour.order
        record.tour.update(
            reference_length_m=reference.length,
            reference_s=time.perf_counter() - started,
            gap_pct=100.0 * (tour.length / reference.length - 1.0) if reference.length else 0.0,
        )
        return tour.order

    # ----------------------------------------------------------------- one cycle
    def _track(
        self,
        plan: ViewPlan,
        segment: NDArray[np.float64],
        yaws: NDArray[np.float64],
        k: int,
        coverage: RegionCoverage,
    ) -> bool:
        """One cycle of Algorithm 1 and the view at its end; False if the pose was unreachable."""
        surface = self._cloud[plan.region.contains(self._cloud, slab=3.0)]
        decision = plan_cycle(
            self.robot.position,
            surface,
            segment,
            yaws,
            self.view,
            gamma_t=self.config.gamma_t,
            adaptive=self.config.adapt,
        )
        if decision.adapt:
            candidates = [
                (decision.local_path.positions[0], decision.local_path.yaws[0]),
                (decision.aligned_global[0], decision.local_path.yaws[0]),
            ]
        else:
            candidates = []
        candidates.append((segment[0], yaws[0]))
        reached = any(self._go_to(point, yaw) for point, yaw in candidates)
        if not reached:
            self._event("view-unreachable", task=plan.region.name, k=k)
            return False
        frame = render(
            self.world,
            self.camera,
            self.robot.position,
            self.robot.quaternion,
            stride=self.config.image_stride,
            stamp=self.robot.time,
        )
        self.current_map.integrate_frame(frame, stride=2)
        coverage.add(frame, self.view.d_view, RANGE_TOLERANCE_M)
        self._cloud = sense(self.robot, self.world, self.current_map)
        self.samples.append(self._sample(plan, k, decision, frame))
        self.frame = frame
        return True

    def _sample(self, plan: ViewPlan, k: int, decision: CycleDecision, frame: Frame) -> ViewSample:
        x, y, z = self.robot.position
        return ViewSample(
            t=self.robot.time,
            task=plan.region.name,
            k=k,
            x=float(x),
            y=float(y),
            z=float(z),
            yaw=self.robot.yaw,
            gamma_s=decision.gamma_s,
            frechet_m=decision.frechet,
            adapted=decision.adapt,
            rmse_before_m=decision.rmse_before,
            rmse_after_m=decision.rmse_after,
            utility=viewpoint_utility(frame.depth, frame.camera.fx),
            view_distance_m=view_distance(frame),
            cycle_ms=1e3 * decision.seconds,
        )

    # ----------------------------------------------------------------- motion on M_C
    def _clear(self, point: NDArray[np.float64], slack: float = 0.0) -> bool:
        radius = self.config.robot_radius + PLANNING_MARGIN_M - slack
        return pose_is_clear(self.current_map, point, radius)

    def _segment_clear(
        self, a: NDArray[np.float64], b: NDArray[np.float64], slack: float = 0.0
    ) -> bool:
        steps = max(2, math.ceil(float(np.linalg.norm(b - a)) / self.current_map.resolution))
        return all(self._clear(a + (b - a) * s, slack) for s in np.linspace(0.0, 1.0, steps)[1:])

    def _go_to(self, goal: NDArray[np.float64], yaw: float | None = None) -> bool:
        """Reach ``goal`` over M_C, sensing every metre and re-planning when the map changes."""
        if not self._clear(goal):
            return False
        for _ in range(20):  # each pass re-plans once on what the last one saw
            if self._segment_clear(self.robot.position, goal):
                waypoints = [goal]
            else:
                try:
                    path = self.planner.plan(self.current_map, self.robot.position, goal)
                except PlanningError:
                    return False
                waypoints = list(path.waypoints[1:])
            outcome = self._drive(waypoints, yaw)
            if outcome != "replan":
                return outcome == "reached"
        return False

    def _drive(self, waypoints: list[NDArray[np.float64]], yaw: float | None) -> str:
        """Follow waypoints in legs of at most a metre: ``reached``, ``replan`` when M_C shows
        the next leg blocked, ``collided`` when the body touched a surface (given up)."""
        for i, point in enumerate(waypoints):
            last = i == len(waypoints) - 1
            while float(np.linalg.norm(point - self.robot.position)) > 1e-6:
                here = self.robot.position
                leg = point - here
                step = min(1.0, SENSE_EVERY_M / max(float(np.linalg.norm(leg)), 1e-9))
                target = here + leg * step
                if not self._segment_clear(here, target, leg_slack(self.current_map.resolution)):
                    return "replan"
                heading = yaw if last else math.atan2(leg[1], leg[0])
                result = self.robot.move_to(target, heading)
                if result.blocked:
                    self._event("collision", at=np.round(result.position, 3).tolist())
                    self._cloud = sense(self.robot, self.world, self.current_map)
                    self._show()
                    return "collided"
                self._cloud = sense(self.robot, self.world, self.current_map)
                self._show()
        return "reached"

    def _navigate(self, route: NDArray[np.float64]) -> None:
        """NavigateToTask: each M_H segment end re-planned over M_C; ends in obstacles skipped."""
        for checkpoint in _checkpoints(route, self.config.segment_m):
            if not self._go_to(checkpoint):
                self._event("segment-end-skipped", at=np.round(checkpoint, 3).tolist())

    def _show(self, frame: Frame | None = None) -> None:
        if self.watch is not None:
            self.watch.step(frame)

    # ----------------------------------------------------------------- results
    @property
    def collisions(self) -> int:
        return sum(event["event"] == "collision" for event in self.events)


def leg_slack(resolution: float) -> float:
    """How much closer than the planned clearance a leg of a planned path may pass.

    The planner keeps cell centres its clearance away from occupied cell centres, while
    :func:`pose_is_clear` samples around a point anywhere in its cell: the two can disagree by
    a cell diagonal. Re-checking a leg with this slack never refuses a path the planner has
    just made (which re-planned the same path until ``_go_to`` gave up), yet still catches an
    obstacle seen on it since.
    """
    return math.sqrt(3.0) * resolution


def _checkpoints(route: NDArray[np.float64], spacing: float) -> list[NDArray[np.float64]]:
    """Points every ``spacing`` metres along a polyline, its end included."""
    points = [route[0]]
    carried = 0.0
    for a, b in itertools.pairwise(route):
        length = float(np.linalg.norm(b - a))
        position = spacing - carried
        while position < length:
            points.append(a + (b - a) * position / length)
            position += spacing
        carried = length - (position - spacing)
    points.append(route[-1])
    return points[1:]


def samples_table(samples: list[ViewSample]) -> dict[str, NDArray]:
    """The time series as columns."""
    if not samples:
        return {name: np.empty(0) for name in ViewSample.__dataclass_fields__}
    return {name: np.array([getattr(s, name) for s in samples]) for name in asdict(samples[0])}
