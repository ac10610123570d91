"""The xFLIE executive: explore, select, approach, inspect and link, until done (000 Sec V).

The loop below is the whole mission; each phase lives in its own module:

1. :mod:`.exploration`: ``π^expl:360``, a survey where the robot stands, registering every
   frame's target detections (eqs 3-5); frontier hops when no target is left.
2. Target selection by utility (eq 6), then :mod:`.approach`: the hierarchical planner over the
   3DLSG for the known part of the route, the local planner (or the volumetric baseline) into
   the unknown, to within ``ε``; the target is confirmed on arrival or discarded.
3. :mod:`.inspection`: ``π^insp``, level by level (eqs 7-10), with :mod:`.surface` giving the
   view steps (002 eqs 1-2) and :mod:`.completion` ending each level (eq 8).
4. :mod:`.links`: Target-layer edges to inspected neighbours; an aerial robot flies back down
   to the target's ``Level-0`` the way it climbed; then ``π^expl:LE``, a survey around the
   inspected target.
5. Repeat until no uninspected target remains and no frontier is left, or the time budget ends.

Every planner call's wall time is recorded by the :class:`MissionRecorder`; with
``charge_planning_time`` the robot also waits for it, so planning costs mission time.
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import TargetNode
from seminspect.mapping.voxel import VoxelMap
from seminspect.missions.xflie.approach import Approach, baseline_planner, local_planner
from seminspect.missions.xflie.config import ResolvedMissionConfig
from seminspect.missions.xflie.context import MissionContext
from seminspect.missions.xflie.exploration import Exploration
from seminspect.missions.xflie.inspection import LevelInspection, platform_vfov
from seminspect.missions.xflie.layout import write_graph
from seminspect.missions.xflie.links import TargetLinks
from seminspect.missions.xflie.metrics import CoverageRecorder
from seminspect.missions.xflie.navigation import Navigator
from seminspect.missions.xflie.recorder import MissionRecorder
from seminspect.missions.xflie.sightings import register_targets
from seminspect.planning.hierarchical import HierarchicalPlanner
from seminspect.planning.utility import UtilityTerms, select_target
from seminspect.planning.view_planner import ViewConstraints
from seminspect.platform.protocol import Platform
from seminspect.runs.directory import RunDirectory
from seminspect.sensors import Frame

#: No new target is started with less simulated time left than this [s].
MIN_INSPECTION_S = 60.0
#: Points this close to the ground are not part of a standing object [m].
GROUND_CLEARANCE = 0.15


@dataclass
class MissionProgress:
    """A snapshot for progress displays."""

    sim_time: float
    budget: float
    phase: str
    detected: int
    inspected: int


class XFlie:
    """One xFLIE mission on a :class:`Platform` (see the module docstring).

    Args:
        config: a resolved configuration.
        platform: the robot.
        occupancy: the robot's (initially unknown) occupancy map of the site's bounding box.
        ground_z: height of the ground where the robot started (it stood on it).
        run: where images and events go (optional).
        progress: called after every step with a :class:`MissionProgress`.
        graph: the 3DLSG to build on, when another robot shares it (default: a new one).
        name: the robot's name in a team (its events carry it).
    """

    def __init__(
        self,
        config: ResolvedMissionConfig,
        platform: Platform,
        occupancy: VoxelMap,
        *,
        ground_z: float,
        run: RunDirectory | None = None,
        progress: Callable[[MissionProgress], None] | None = None,
        graph: LayeredSemanticGraph | None = None,
        name: str | None = None,
    ) -> None:
        self.config = config
        self.params = config.params
        self.platform = platform
        self.occupancy = occupancy
        self.run = run
        self.progress = progress
        self.phase = "start"
        self.stop_reason = ""
        #: The last target selection's winner and its eq (6) terms (None: none yet, or none left).
        self.choice: UtilityTerms | None = None
        self.graph = (
            graph
            if graph is not None
            else LayeredSemanticGraph(self.params, robot_position=platform.position)
        )
        self.planner = HierarchicalPlanner(self.graph)
        self.recorder = MissionRecorder(
            lambda: platform.time, CoverageRecorder(config.inspection.d_view), run, name
        )
        self.local = local_planner(config)
        self.navigator = Navigator(
            platform,
            occupancy,
            self.local,
            self._on_transit_frame,
            lidar_every_m=config.exploration.lidar_every_m,
            camera_every_m=config.exploration.camera_every_m,
            clear_misses_to=self.params.d_max,
            carving_spacing=config.map_carving_spacing,
            timers=self.recorder.timers,
            charge_planning_time=config.charge_planning_time,
            guard_unknown=config.mode == "aerial",
        )
        self.ctx = MissionContext(
            config,
            platform,
            occupancy,
            self.graph,
            self.navigator,
            self.recorder,
            run,
            min_height=ground_z + GROUND_CLEARANCE,
            on_step=self._report,
        )
        self.exploration = Exploration(self.ctx)
        self._build_target_phases()

    def _build_target_phases(self) -> None:
        """The phases that reach, inspect and link targets (a mission that only explores
        builds none)."""
        inspection = self.config.inspection
        view = ViewConstraints(
            d_view=inspection.d_view,
            overlap_h=inspection.overlap_h,
            overlap_v=inspection.overlap_v,
            hfov_deg=self.params.fov_deg,
            vfov_deg=platform_vfov(self.params),
        )
        #: The paper's baseline planner between targets (``planner="volumetric"``).
        self.volumetric = baseline_planner(self.config)
        self.approach = Approach(self.ctx, self.planner, self.volumetric)
        self.inspection = LevelInspection(self.ctx, view, self.platform.camera_pitch)
        self.links = TargetLinks(self.ctx, self.local)

    @property
    def time_left(self) -> float:
        return self.ctx.time_left

    @property
    def unreachable(self) -> set[str]:
        """Targets given up on: not reached, or too few views to inspect."""
        return self.ctx.unreachable

    def execute(self) -> str:
        """Run until done or out of time; returns why it stopped."""
        self.begin()
        frontier_hops = 0
        while self.time_left > MIN_INSPECTION_S:
            choice = self.select()
            if choice is None:
                if frontier_hops >= self.config.exploration.frontier_max_hops or not self.explore():
                    self.stop_reason = "no uninspected target and no frontier left"
                    break
                frontier_hops += 1
                continue
            if self.pursue(self.graph.target(choice.target_id)):
                self._phase("explore-LE")
                self.exploration.survey()
        if not self.stop_reason:
            self.stop_reason = "time budget spent"
        return self.stop_reason

    def begin(self) -> None:
        """``π^expl:360`` where the robot starts, after a first LiDAR scan."""
        self._phase("explore-360")
        self.navigator.sense_lidar()
        self.exploration.survey()

    def select(self, taken: Collection[str] = ()) -> UtilityTerms | None:
        """The next target by eq (6) from the robot state in the graph (None: none left);
        targets given up on and those in ``taken`` (another robot's) are not candidates."""
        choice, terms = select_target(self.graph, exclude=self.unreachable.union(taken))
        self._log_utilities(choice, terms)
        self.choice = choice
        return choice

    def pursue(self, target: TargetNode) -> bool:
        """Approach a selected target, confirm it and inspect it; False when it was not
        reached (it joins the unreachable ones) or not confirmed (it is discarded)."""
        self._phase("navigate")
        if not self.approach.reach(target):
            self.unreachable.add(target.id)
            self.ctx.event("unreachable", target=target.id)
            return False
        if not self.approach.confirm(target):
            self.graph.discard_target(target.id)
            self.ctx.event("discarded", target=target.id, reason="not re-observed on arrival")
            return False
        self.inspect(target)
        return True

    def explore(self, keep: Callable[[NDArray[np.float64]], bool] | None = None) -> bool:
        """A frontier hop and a survey there; False when no frontier is left (among those
        whose goal ``keep`` accepts, when given)."""
        self._phase("explore-frontier")
        return self.exploration.explore(keep)

    def inspect(self, target: TargetNode) -> None:
        """``π^insp`` on one target, then its Target-layer links and a graph snapshot."""
        self._phase("inspect")
        if not self.inspection.inspect(target):
            return
        self.links.connect(target)
        self.ctx.event(
            "inspected",
            target=target.id,
            position=target.position.round(2).tolist(),
            levels=len(target.levels),
        )
        if self.run is not None:
            write_graph(self.run, self.graph, snapshot_time=self.platform.time)
            self.run.flush_events()
        if self.config.mode == "aerial":
            self.approach.descend(target)

    def _on_transit_frame(self, frame: Frame) -> None:
        """A frame the navigator took while driving: into the map, and its targets registered."""
        self.ctx.integrate(frame)
        register_targets(self.ctx, frame)

    def _phase(self, name: str) -> None:
        self.phase = name
        self._report()

    def _report(self) -> None:
        if self.progress is not None:
            targets = self.graph.targets()
            self.progress(
                MissionProgress(
                    self.platform.time,
                    self.config.time_budget_s,
                    self.phase,
                    len(targets),
                    sum(t.inspected for t in targets),
                )
            )

    def _log_utilities(self, choice: UtilityTerms | None, terms: list[UtilityTerms]) -> None:
        """Record every candidate's eq (6) terms at a decision (for the utility picture)."""
        if terms:
            self.ctx.event(
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
