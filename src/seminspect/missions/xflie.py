"""The xFLIE executive: explore, select, navigate, inspect and remember (000 Sec V).

One mission, step by step:

1. ``π^expl:360``: a 360-degree survey where the robot stands. Every frame's target
   detections are registered (eq 3) and the Target layer is optimised and merged (eqs 4-5).
2. Target selection by utility (eq 6). Navigation: the hierarchical planner over the 3DLSG for
   the known part of the route (to the inspected target nearest the goal), then the local
   planner on the robot's own occupancy map into unknown space, to within ``ε`` of the target.
   With ``planner="volumetric"`` (000 Sec VII-D's baseline) the volumetric planner, rebuilt on
   the robot's map at 0.4 m for every query, plans the whole way instead.
3. ``π^insp``: ``Level-0`` starts at the target (eq 7). At every view the pose is registered
   (eq 9) with its image, part detections go to the interim Pose-Feature graph, and FLIE's local
   view planner (002 eqs 1-2) gives the next view. A level ends when, back within
   ``d_thresh^I`` of its start, the view matches the level's first ``N`` images (eq 8,
   ``Γ >= Γ_thresh``); each level is then pruned (eq 10). Aerial robots climb by the vertical
   overlap until the target's height is covered; ground robots do one level.
4. After inspection: containment polygon, centroid refinement, Target-layer edges to inspected
   neighbours (realised by routes through known free space), then ``π^expl:LE``, a survey
   around the inspected target.
5. Repeat until no uninspected target remains (then visit exploration frontiers to find more)
   or the time budget ends.

Every planner call's wall time (routes, graph queries, Target-layer edges, view poses) is
recorded; with ``charge_planning_time`` the robot also waits for it, so planning costs mission
time as on a real robot.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage
from scipy.spatial import cKDTree

from seminspect.core.errors import PlanningError
from seminspect.core.params import InspectionParams
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import TargetNode, TargetStatus
from seminspect.mapping.voxel import VoxelMap
from seminspect.missions.config import MissionConfig, inspection_params, survey_headings
from seminspect.missions.metrics import CoverageRecorder, Timers
from seminspect.missions.navigation import Navigator, find_frontiers
from seminspect.missions.platform import Platform, heading_to
from seminspect.missions.rundir import RunDirectory
from seminspect.perception.detections import detection_points, observe
from seminspect.perception.observation import Observation
from seminspect.perception.similarity import (
    ORB_GAMMA_THRESHOLD,
    ImageFeatures,
    SceneMatcher,
    scene_similarity,
)
from seminspect.planning.grid_search import GridPath
from seminspect.planning.gridmap import CostModel
from seminspect.planning.hierarchical import HierarchicalPlanner, RoutePlan
from seminspect.planning.local import LocalPlanner
from seminspect.planning.smoothing import refine_path
from seminspect.planning.utility import UtilityTerms, select_target
from seminspect.planning.view_planner import ViewConstraints, next_view_pose
from seminspect.planning.volumetric import RebuildingVolumetricPlanner
from seminspect.sensors import Detection, Frame

#: Voxel size of the cloud kept of the target under inspection [m].
TARGET_VOXEL = 0.2
#: LiDAR returns closer than this to the target's cloud belong to it or stand beside it [m].
ATTACHED = 1.5
#: Fractions of the full view-planner step tried, in order, when a step is blocked.
STEP_SCALES = (1.0, 0.5, 0.25)
#: Fractions of the viewing distance tried, in order, when no step is free at the full one.
VIEW_DISTANCE_SCALES = (1.0, 0.75)
#: Every DEPTH_STRIDE-th pixel (rows and columns) of a depth frame goes into the map.
DEPTH_STRIDE = 8
#: A view move shorter than this does not count as a step along the surface [m].
MIN_VIEW_STEP = 0.1
#: Frontiers nearer than this to the robot (or to one already visited) are not worth a trip [m].
FRONTIER_MIN_DISTANCE = 3.0
#: No new target is started with less simulated time left than this [s].
MIN_INSPECTION_S = 60.0
#: Points this close to the ground are not part of a standing object [m].
GROUND_CLEARANCE = 0.15
#: Extra clearance added to the robot radius in the planners' inflation [m].
PLANNING_MARGIN = 0.2
#: A level also ends (as a safety cap) once the robot has circled the target this far [rad].
LEVEL_SWEEP_CAP = 2.0 * math.pi + math.radians(40)
#: A part belongs to the inspected target when this share of its mask lies on the target's.
PART_OVERLAP = 0.5
#: The volumetric baseline's map resolution and risk band (000 Sec VII-D: D*+ on M_0.4, risk
#: parameter 0.2) [m].
BASELINE_RESOLUTION = 0.4
BASELINE_RISK_RADIUS = 0.2


@dataclass
class MissionProgress:
    """A snapshot for progress displays."""

    sim_time: float
    budget: float
    phase: str
    detected: int
    inspected: int


@dataclass
class PlanningRecord:
    """One hierarchical planning query made during the mission."""

    goal: str
    seconds: float
    target_layer_s: float
    local_layers_s: float
    length: float
    settled: int


@dataclass
class _Level:
    """Bookkeeping for the level being inspected."""

    start: NDArray[np.float64]
    candidates: list[ImageFeatures] = field(default_factory=list)
    left_start: bool = False
    poses: int = 0
    sweep: float = 0.0
    last_bearing: float | None = None


class XFlie:
    """One xFLIE mission on a :class:`Platform` (see the module docstring).

    Args:
        config: a resolved :class:`MissionConfig`.
        platform: the robot.
        occupancy: the robot's (initially unknown) occupancy map of the site's bounding box.
        ground_z: height of the ground where the robot started (it stood on it).
        run: where images and events go (optional).
        progress: called after every step with a :class:`MissionProgress`.
    """

    def __init__(
        self,
        config: MissionConfig,
        platform: Platform,
        occupancy: VoxelMap,
        *,
        ground_z: float,
        run: RunDirectory | None = None,
        progress: Callable[[MissionProgress], None] | None = None,
    ) -> None:
        assert config.inspection is not None and config.time_budget_s is not None
        #: Camera tilt below the horizon [rad] (the platform's, when it reports one).
        self.camera_pitch = float(getattr(platform, "camera_pitch", 0.0))
        #: Object points below this height are bled pixels on the ground, not the object.
        self.min_height = ground_z + GROUND_CLEARANCE
        self.config = config
        self.params = inspection_params(config)
        self.platform = platform
        self.occupancy = occupancy
        self.run = run
        self.progress = progress
        self.budget = config.time_budget_s
        self.graph = LayeredSemanticGraph(self.params, robot_position=platform.position)
        self.planner = HierarchicalPlanner(self.graph)
        self.timers = Timers()
        self.coverage = CoverageRecorder(config.inspection.d_view)
        self.matcher = SceneMatcher()
        self.gamma_thresh = (
            ORB_GAMMA_THRESHOLD if config.gamma_thresh is None else config.gamma_thresh
        )
        self.view = ViewConstraints(
            d_view=config.inspection.d_view,
            overlap_h=config.inspection.overlap_h,
            overlap_v=config.inspection.overlap_v,
            hfov_deg=self.params.fov_deg,
            vfov_deg=platform_vfov(self.params),
        )
        clearance = config.robot.radius + PLANNING_MARGIN
        model = CostModel(clearance, risk_radius=0.3, unknown_cost=1.0)
        band = config.robot.planning_band()
        self.local = LocalPlanner(model, config.mode or "ground", band=band)
        #: The paper's baseline planner between targets (``planner="volumetric"``).
        self.volumetric = (
            RebuildingVolumetricPlanner(
                CostModel(clearance, risk_radius=BASELINE_RISK_RADIUS, unknown_cost=1.0),
                band if config.mode == "ground" else None,
                resolution=BASELINE_RESOLUTION,
            )
            if config.planner == "volumetric"
            else None
        )
        self.navigator = Navigator(
            platform,
            occupancy,
            self.local,
            self._on_transit_frame,
            lidar_every_m=config.exploration.lidar_every_m,
            camera_every_m=config.exploration.camera_every_m,
            clear_misses_to=self.params.d_max,
            timers=self.timers,
            charge_planning_time=config.charge_planning_time,
        )
        self.target_cloud = PointSet(TARGET_VOXEL)
        self.unreachable: set[str] = set()
        self.spent_frontiers: list[NDArray[np.float64]] = []
        self.hierarchical: list[PlanningRecord] = []
        self.level_endings: dict[str, int] = {"similarity": 0, "cap": 0}
        self.phase = "start"
        self.stop_reason = ""
        self._frame_count = 0

    # ----------------------------------------------------------------- top level
    @property
    def time_left(self) -> float:
        return self.budget - self.platform.time

    def execute(self) -> str:
        """Run until done or out of time; returns why it stopped."""
        self._phase("explore-360")
        self.navigator.sense_lidar()
        self.survey()
        frontier_hops = 0
        while self.time_left > MIN_INSPECTION_S:
            choice, terms = select_target(self.graph, exclude=self.unreachable)
            self._log_utilities(choice, terms)
            if choice is None:
                if frontier_hops >= self.config.exploration.frontier_max_hops or not self.explore():
                    self.stop_reason = "no uninspected target and no frontier left"
                    break
                frontier_hops += 1
                continue
            target = self.graph.target(choice.target_id)
            if not self.reach(target):
                self.unreachable.add(target.id)
                self._event("unreachable", target=target.id)
                continue
            if not self.confirm(target):
                self.graph.discard_target(target.id)
                self._event("discarded", target=target.id, reason="not re-observed on arrival")
                continue
            self.inspect(target)
            self._phase("explore-LE")
            self.survey()
        if not self.stop_reason:
            self.stop_reason = "time budget spent"
        return self.stop_reason

    def _phase(self, name: str) -> None:
        self.phase = name
        self._report()

    def _report(self) -> None:
        if self.progress is not None:
            targets = self.graph.targets()
            self.progress(
                MissionProgress(
                    self.platform.time,
                    self.budget,
                    self.phase,
                    len(targets),
                    sum(t.inspected for t in targets),
                )
            )

    def _event(self, kind: str, **fields: object) -> None:
        if self.run is not None:
            self.run.log_event(kind, self.platform.time, **fields)

    # ----------------------------------------------------------------- exploration
    def survey(self) -> None:
        """``π^expl:360``: turn on the spot, registering every frame's detections."""
        count = survey_headings(self.params.fov_deg, self.config.exploration.survey_overlap)
        start = self.platform.yaw
        for k in range(count):
            if self.time_left <= 0:
                return
            self.platform.turn_to(start + k * 2.0 * math.pi / count)
            self.register_targets(self._capture())
        self._report()

    def explore(self) -> bool:
        """Drive to the nearest reachable frontier and survey there; False if none is left.

        Frontiers within ``FRONTIER_MIN_DISTANCE`` of the robot are skipped: they are the ring
        of ground around its own body that no sensor sees, which no trip resolves. A frontier
        visited or found unreachable is not chosen again.
        """
        self._phase("explore-frontier")
        band = self.local.band or (self.platform.position[2] - 1.0, self.platform.position[2] + 1.0)
        frontiers = find_frontiers(
            self.occupancy,
            band,
            self.config.exploration.frontier_min_cells,
            self.platform.position[2],
        )
        here = self.platform.position

        def distance(goal: NDArray[np.float64]) -> float:
            return float(np.linalg.norm((goal - here)[:2]))

        candidates = [
            f
            for f in frontiers
            if distance(f.goal) >= FRONTIER_MIN_DISTANCE and not self._spent_frontier(f.goal)
        ]
        candidates.sort(key=lambda f: distance(f.goal))
        for frontier in candidates[:5]:
            self.spent_frontiers.append(frontier.goal)
            if self.navigator.go_to(frontier.goal, radius=1.5):
                self._event("frontier", goal=frontier.goal.round(2).tolist(), cells=frontier.cells)
                self.survey()
                return True
        return False

    def _spent_frontier(self, goal: NDArray[np.float64]) -> bool:
        return any(
            np.linalg.norm((goal - f)[:2]) < FRONTIER_MIN_DISTANCE for f in self.spent_frontiers
        )

    # ----------------------------------------------------------------- perception
    def _capture(self) -> Frame:
        with self.timers("sensing"):
            frame = self.platform.capture()
            self.occupancy.integrate_frame(frame, stride=DEPTH_STRIDE, use_odometry=True)
        self._frame_count += 1
        return frame

    def _on_transit_frame(self, frame: Frame) -> None:
        with self.timers("sensing"):
            self.occupancy.integrate_frame(frame, stride=DEPTH_STRIDE, use_odometry=True)
        self._frame_count += 1
        self.register_targets(frame)

    def _detect(self, frame: Frame, level: str, labels: Iterable[str]) -> list[Detection]:
        """Segmentations at or above the confidence threshold."""
        detections = self.platform.detect(frame, level, labels)
        return [d for d in detections if d.score >= self.config.min_score]

    def register_targets(self, frame: Frame) -> None:
        """Eqs (3)-(5) for one frame: register its detections, optimise, merge."""
        with self.timers("perception"):
            detections = self._detect(frame, "instance", self.config.target_classes or ())
            observations = [
                observe(
                    frame,
                    d,
                    method=self.config.localisation,
                    erosion_px=self.config.mask_erosion_px,
                    min_height=self.min_height,
                    max_range=self.params.d_max,
                )
                for d in detections
            ]
        with self.timers("graph"):
            for z in observations:
                if z is not None:
                    self.graph.register_target(z)
            self.graph.update_robot(
                frame.odometry_position, frame.odometry_orientation, frame.stamp
            )
            update = self.graph.optimise_targets()
        for added in update.added:
            self._event(
                "detected",
                target=added,
                position=self.graph.target(added).position.round(2).tolist(),
            )

    # ----------------------------------------------------------------- navigation
    def reach(self, target: TargetNode) -> bool:
        """Navigate to within ``ε`` of a detected target (eq 2's proximity condition)."""
        self._phase("navigate")
        goal = target.position
        self._event("selected", target=target.id, utility=round(target.utility, 4))
        self._hierarchical_leg(goal)
        for radius in (self.params.epsilon, self.params.epsilon + 1.0, self.params.epsilon + 2.5):
            arrived = self.navigator.go_to(goal, radius, planner=self.volumetric)
            if arrived:
                self._event("arrived", target=target.id)
                return True
            if self.time_left <= 0:
                return False
        return False

    def confirm(self, target: TargetNode) -> bool:
        """Look for the target from where the robot arrived: straight at it, then either side.

        A detection that is not there when the robot comes to look (a false positive of the
        segmentation, or a badly localised one) is discarded rather than inspected.
        """
        facing = heading_to(self.platform.position, target.position)
        for offset in (0.0, math.radians(35), -math.radians(35)):
            self.platform.turn_to(facing + offset)
            frame = self._capture()
            self.register_targets(frame)
            if target.id not in self.graph:  # merged away by eq (4) after a better view
                return False
            _, points = self._target_view(frame, target, self.params.d_check_T)
            if len(points):
                self.platform.turn_to(facing)
                return True
        return False

    def _hierarchical_leg(self, goal: NDArray[np.float64]) -> None:
        """The known part of the route: over the 3DLSG to the traversable node nearest ``goal``."""
        if not self.graph.targets(TargetStatus.INSPECTED) or self.config.planner != "hierarchical":
            return
        with self.timers("planning"):
            entry = self.planner.nearest_entry(goal)
            entry_position = self.graph.node(entry).position
            here = self.platform.position
            if np.linalg.norm((goal - entry_position)[:2]) + 5.0 >= np.linalg.norm(
                (goal - here)[:2]
            ):
                return  # the graph gets the robot no closer than driving straight for it
            try:
                plan = self.planner.plan(entry, here)
            except PlanningError:  # the Target layer does not join the two; drive without it
                return
            self.record_plan(entry, plan)
            refined = refine_path(plan.waypoints, self.navigator.cost_grid())
            self.navigator.planned(plan.timing.total_s + refined.refine_time)
            route = refined.waypoints
        self.navigator.drive(route)

    # ----------------------------------------------------------------- inspection
    def inspect(self, target: TargetNode) -> None:
        """``π^insp`` on one target, level by level, then the post-inspection updates."""
        self._phase("inspect")
        assert self.config.inspection is not None
        start = self._view_pose(image=None)
        self.target_cloud = PointSet(TARGET_VOXEL)
        self._closed_levels: list[bool] = []
        with self.timers("graph"):
            self.graph.begin_inspection(target.id, start)
        heights: list[float] = []
        for level in range(self.config.inspection.max_levels):
            if level > 0 and not self._climb(target, heights):
                break
            self._inspect_level(target, heights)
            self._close_level()
            if self.config.mode != "aerial" or self.time_left <= 0:
                break
        if len(LayeredSemanticGraph.entry_level(target).poses) < 3:
            with self.timers("graph"):
                self.graph.cancel_inspection()
            self.unreachable.add(target.id)
            self._event("inspection-cancelled", target=target.id, reason="too few views")
            return
        closed = [i for i, done in enumerate(self._closed_levels) if done]
        with self.timers("graph"):
            self.graph.finish_inspection(polygon_level=closed[0] if closed else 0)
        for pruned in self.graph.pruned:
            self._event("discarded", target=pruned, reason=f"re-detection of {target.id}")
        self._connect_inspected(target)
        self._event(
            "inspected",
            target=target.id,
            position=target.position.round(2).tolist(),
            levels=len(target.levels),
        )
        if self.run is not None:
            self.run.write_graph(self.graph, snapshot_time=self.platform.time)
            self.run.flush_events()

    def _view_pose(self, image: str | None) -> Observation:
        return Observation.view_pose(
            self.platform.position,
            quat_from_yaw(self.platform.yaw),
            image=image,
            stamp=self.platform.time,
        )

    def _inspect_level(self, target: TargetNode, heights: list[float]) -> None:
        assert self.config.inspection is not None
        state = _Level(self.platform.position.copy())
        surface = np.empty((0, 3))
        while self.time_left > 0:
            frame = self._capture()
            mask, points = self._target_view(frame, target)
            if len(points):
                heights.append(float(points[:, 2].max()))
                self.target_cloud.add(points)
            visible = self._surface(points)
            if len(visible):  # out of sight for a moment (a corner): keep the last surface
                surface = visible
            self._register_view(target, frame, mask, points)
            state.poses += 1
            if self._level_complete(state, frame, target, surface):
                self._closed_levels.append(True)
                return
            if not self._step_along(surface, target):
                break
        self._closed_levels.append(False)

    def _surface(self, mask_points: NDArray[np.float64]) -> NDArray[np.float64]:
        """What the view planner steps along: the target's points in view, and every LiDAR
        return attached to the target (within ``ATTACHED`` of anything seen of it), so that
        parts of it out of the camera's view and debris beside it are kept at a distance too."""
        scan = self.navigator.last_scan
        if scan is None or not self.target_cloud.size:
            return mask_points
        returns = scan.points[scan.points[:, 2] >= self.min_height]
        attached = returns[self.target_cloud.near(returns, ATTACHED)]
        return np.vstack([mask_points, attached]) if len(mask_points) else attached

    def _target_view(
        self, frame: Frame, target: TargetNode, gate: float | None = None
    ) -> tuple[NDArray[np.bool_] | None, NDArray[np.float64]]:
        """The mask and points of the target in this frame: the nearest detection of its label
        whose points lie within ``gate`` (default ``2 d_check^T``) of the target."""
        gate = 2.0 * self.params.d_check_T if gate is None else gate
        with self.timers("perception"):
            detections = self._detect(frame, "instance", [target.label])
            best: tuple[float, Detection, NDArray[np.float64]] | None = None
            for detection in detections:
                points = detection_points(
                    frame, detection, self.config.mask_erosion_px, self.min_height
                )
                if not len(points):
                    continue
                distance = float(
                    np.linalg.norm(np.median(points, axis=0)[:2] - target.position[:2])
                )
                if distance <= gate and (best is None or distance < best[0]):
                    best = (distance, detection, points)
        if best is None:
            return None, np.empty((0, 3))
        return best[1].mask, best[2]

    def _register_view(
        self,
        target: TargetNode,
        frame: Frame,
        mask: NDArray[np.bool_] | None,
        points: NDArray[np.float64],
    ) -> None:
        """Eq (9) for the view, and its features into the interim ``G~^PF``."""
        assert self.config.inspection is not None
        image = None
        if self.run is not None and self.config.inspection.save_images:
            image = self.run.write_image(f"{target.id}-{self._frame_count:05d}", frame.intensity)
        with self.timers("graph"):
            self.graph.register_pose(self._view_pose(image))
        self.coverage.add_frame(target.id, frame, points)
        if mask is None:
            return
        grown = dilate(mask, 5)
        with self.timers("perception"):
            parts = self._detect(frame, "part", self.config.feature_labels or ())
            features = [
                observe(frame, p, image=image, method="median")
                for p in parts
                if (p.mask & grown).sum() >= PART_OVERLAP * p.area_px
            ]
        with self.timers("graph"):
            for z in features:
                if z is not None:
                    self.graph.register_feature(z)

    def _level_complete(
        self, state: _Level, frame: Frame, target: TargetNode, surface: NDArray[np.float64]
    ) -> bool:
        """Eq (8) scene similarity, with a sweep and pose cap as a safety net."""
        assert self.config.inspection is not None
        with self.timers("perception"):
            features = self.matcher.features(frame.intensity)
        distance = float(np.linalg.norm(self.platform.position - state.start))
        state.left_start |= distance > self.params.d_thresh_I
        seen = self.target_cloud.points
        centre = seen.mean(axis=0) if len(seen) else target.position
        bearing = heading_to(centre, self.platform.position)
        if state.last_bearing is not None:
            state.sweep += abs(math.remainder(bearing - state.last_bearing, math.tau))
        state.last_bearing = bearing
        if len(state.candidates) < self.params.horizon_N:
            state.candidates.append(features)
            return False
        if state.left_start:
            with self.timers("perception"):
                gamma = scene_similarity(
                    self.matcher, features, state.candidates, distance, self.params.d_thresh_I
                )
            if gamma >= self.gamma_thresh:
                self.level_endings["similarity"] += 1
                self._event(
                    "level-complete",
                    target=target.id,
                    gamma=round(gamma, 3),
                    poses=state.poses,
                    reason="similarity",
                )
                return True
        if (
            state.sweep >= LEVEL_SWEEP_CAP
            or state.poses >= self.config.inspection.max_poses_per_level
        ):
            self.level_endings["cap"] += 1
            self._event("level-complete", target=target.id, poses=state.poses, reason="cap")
            return True
        return False

    def _step_along(self, surface: NDArray[np.float64], target: TargetNode) -> bool:
        """Move to the next view pose of 002 eqs (1)-(2); False when no step is possible.

        When the full step is blocked, shorter steps along the surface are tried, and then the
        same steps from closer to the surface (where the space around the target is too tight
        for the viewing distance, as beside a car in a tunnel), before giving up.
        """
        points = self._surface_in_view(surface) if len(surface) else target.position[None, :]
        for closer, scale in itertools.product(VIEW_DISTANCE_SCALES, STEP_SCALES):
            overlap = 1.0 - (1.0 - self.view.overlap_h) * scale
            view = self.view.model_copy(
                update={"overlap_h": overlap, "d_view": self.view.d_view * closer}
            )
            with self.timers("planning"):
                started = time.perf_counter()
                try:
                    pose = next_view_pose(self.platform.position, points, view)
                except PlanningError:
                    return False
                finally:
                    self.navigator.planned(time.perf_counter() - started)
            if self._move_to_view(pose.position, pose.yaw):
                return True
        return False

    def _surface_in_view(self, surface: NDArray[np.float64]) -> NDArray[np.float64]:
        """The surface up to the top of the view: parts above it do not limit the level, while
        anything below the robot (a collapsed slab, rubble) must keep its distance too."""
        reach = math.tan(math.radians(self.view.vfov_deg) / 2) * self.view.d_view
        below = surface[surface[:, 2] <= self.platform.position[2] + reach]
        return below if len(below) else surface

    def _move_to_view(self, goal: NDArray[np.float64], yaw: float) -> bool:
        """A short move beside the structure. Aerial robots keep to space they have seen to be
        free: below and beside a flying robot lies what its sensors see least."""
        known_only = self.config.mode == "aerial"
        if self.config.mode == "ground":
            goal = np.array([goal[0], goal[1], self.platform.position[2]])
        step = float(np.linalg.norm(goal - self.platform.position))
        if step < MIN_VIEW_STEP:
            return False
        if self.navigator.segment_is_free(self.platform.position, goal, known_only=known_only):
            with self.timers("driving"):
                motion = self.platform.move_to(goal, yaw)
            self.navigator.mark_contact(motion.contact)
            self.navigator.sense_lidar()
            if motion.reached:
                return True
        return self.navigator.go_to(
            goal, radius=min(0.5, 0.25 * step), final_yaw=yaw, attempts=2, known_only=known_only
        )

    def _climb(self, target: TargetNode, heights: list[float]) -> bool:
        """Start the next level one vertical step up, while the target rises above the view."""
        top = max(heights) if heights else target.position[2]
        half = math.radians(self.view.vfov_deg) / 2
        reach = self.view.d_view * math.tan(half - self.camera_pitch)
        if self.platform.position[2] + reach >= top:
            return False
        here = self.platform.position
        goal = here + np.array([0.0, 0.0, self.view.vertical_step])
        with self.timers("driving"):
            motion = self.platform.move_to(goal, self.platform.yaw)
        if not motion.reached:
            return False
        with self.timers("graph"):
            self.graph.begin_level(self._view_pose(image=None), via=self._climb_route(here))
        self._event("level", target=target.id, height=round(float(goal[2]), 2))
        return True

    def _close_level(self) -> None:
        """Eq (10) for the level just inspected. Its ring edge (last pose back to the level's
        start) is a straight segment the robot never drove, so it is added only where the
        robot's map shows that segment free (known space, the planners' clearance)."""
        level = self.graph.current_level
        assert level is not None
        poses = level.poses
        ring = len(poses) > 1 and self.navigator.segment_is_free(
            poses[-1].position, level.position, known_only=True
        )
        with self.timers("graph"):
            self.graph.close_level(close_ring=ring)
        if len(poses) > 1 and not ring:
            self._event("ring-left-open", level=level.id)

    def _climb_route(self, climb_start: NDArray[np.float64]) -> NDArray[np.float64]:
        """How the robot got from the closing level's start to where it climbed: through the
        ring edge when the level kept it, otherwise along its view poses as it drove them."""
        level = self.graph.current_level
        assert level is not None
        poses = level.poses
        ring = len(poses) > 1 and self.graph.edge(poses[-1].id, level.id) is not None
        chain = [p.position for p in (poses[-1:] if ring else poses)]
        if not chain or np.linalg.norm(chain[-1] - climb_start) > 1e-9:
            chain.append(climb_start)
        return np.array(chain)

    def _connect_inspected(self, target: TargetNode) -> None:
        """``v_I - v_I`` edges to the nearest inspected targets, through known free space.

        The robot does not drive these routes now, so they keep half a cell diagonal more
        clearance than its routes where they can: the planner measures between cell centres,
        and a straight segment may pass anywhere within the cells it crosses. Where no route
        keeps it, the robot's own clearance is used, so the Target layer stays as connected.
        """
        inspected = [t for t in self.graph.targets(TargetStatus.INSPECTED) if t is not target]
        entry = LayeredSemanticGraph.entry_level(target).position
        inspected.sort(
            key=lambda t: float(
                np.linalg.norm(LayeredSemanticGraph.entry_level(t).position - entry)
            )
        )
        dims = 2 if self.local.mode == "ground" else 3
        slack = 0.5 * self.occupancy.resolution * math.sqrt(dims)
        planners = [
            LocalPlanner(
                CostModel(self.local.model.robot_radius + extra, 0.0, unknown_cost=None),
                self.local.mode,
                band=self.local.band or (0.3, 1.5),
            )
            for extra in (slack, 0.0)
        ]
        for other in inspected[:3]:
            start = LayeredSemanticGraph.entry_level(other).position
            with self.timers("planning"):
                started = time.perf_counter()
                path = _first_route(planners, self.occupancy, start, entry)
                self.navigator.planned(time.perf_counter() - started)
            if path is None:
                continue
            via = path.waypoints[1:-1]
            with self.timers("graph"):
                self.graph.connect_targets(other.id, target.id, via if len(via) else None)

    # ----------------------------------------------------------------- logs
    def record_plan(self, goal: str, plan: RoutePlan) -> None:
        """Keep a hierarchical query's timing for the Table 3 planning-time column."""
        self.hierarchical.append(
            PlanningRecord(
                goal,
                plan.timing.total_s,
                plan.timing.target_layer_s,
                plan.timing.local_layers_s,
                plan.length,
                plan.settled,
            )
        )

    def _log_utilities(self, choice: UtilityTerms | None, terms: list[UtilityTerms]) -> None:
        """Record every candidate's eq (6) terms at a decision (for the utility picture)."""
        if terms:
            self._event(
                "utilities",
                chosen=None if choice is None else choice.target_id,
                terms={
                    t.target_id: [
                        round(t.utility, 4),
                        round(t.proximity, 4),
                        round(t.area, 5),
                        round(t.centrality, 4),
                    ]
                    for t in terms
                },
            )


def _first_route(
    planners: Iterable[LocalPlanner],
    occupancy: VoxelMap,
    start: NDArray[np.float64],
    goal: NDArray[np.float64],
) -> GridPath | None:
    """The route of the first planner that finds one, if any."""
    for planner in planners:
        try:
            return planner.plan(occupancy, start, goal)
        except PlanningError:
            continue
    return None


class PointSet:
    """Points thinned to one per voxel, with radius queries."""

    def __init__(self, voxel: float) -> None:
        self.voxel = voxel
        self.points = np.empty((0, 3))
        self._tree: cKDTree | None = None

    @property
    def size(self) -> int:
        return len(self.points)

    def add(self, points: NDArray[np.float64]) -> None:
        merged = np.vstack([self.points, points])
        _, first = np.unique(
            np.floor(merged / self.voxel).astype(np.int64), axis=0, return_index=True
        )
        self.points = merged[np.sort(first)]
        self._tree = None

    def near(self, points: NDArray[np.float64], radius: float) -> NDArray[np.bool_]:
        """Which ``points`` lie within ``radius`` of the set."""
        if self._tree is None:
            self._tree = cKDTree(self.points)
        distance, _ = self._tree.query(points, distance_upper_bound=radius)
        return np.isfinite(distance)


def dilate(mask: NDArray[np.bool_], pixels: int) -> NDArray[np.bool_]:
    """Grow a mask by ``pixels`` (square structuring element)."""
    return ndimage.binary_dilation(mask, iterations=pixels)


def platform_vfov(params: InspectionParams) -> float:
    """Vertical field of view of a ``I_w x I_h`` camera with horizontal FOV ``α``."""
    half = math.atan(math.tan(params.fov_rad / 2) * params.image_height / params.image_width)
    return math.degrees(2 * half)
