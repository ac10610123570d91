"""Mission measurements and the run's figures: where wall time goes, CPU load, inspection
coverage (000 Table 6), and :class:`MissionMetrics`, the typed form of ``metrics.json``.

**Inspection coverage** is measured two ways:

* *surface coverage* (ours): the share of a target's outward surface area that some inspection
  image saw from within ``1.5 x d_view``. Faces pointing down (normal z < -0.5, under a vehicle)
  are left out, since no view from outside can see them;
* *bounding-box volume* (the paper's m^3): the volume of the axis-aligned box around every
  point of the target's masks during its inspection, summed over targets, and its ratio to the
  true boxes' volume.
"""

from __future__ import annotations

import time
from collections import defaultdict
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
import psutil
from numpy.typing import NDArray

from seminspect.missions.xflie.scoring import Match
from seminspect.sensors import Frame
from seminspect.worlds import World

#: A face counts as inspected when seen from closer than this many viewing distances.
VIEW_RANGE_FACTOR = 1.5


class Timers:
    """Wall-clock seconds per category (``with timers("sensing"): ...``), nesting excluded."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = defaultdict(float)
        self._stack: list[str] = []

    @contextmanager
    def __call__(self, category: str) -> Iterator[None]:
        start = time.perf_counter()
        self._stack.append(category)
        try:
            yield
        finally:
            self._stack.pop()
            elapsed = time.perf_counter() - start
            self.seconds[category] += elapsed
            if self._stack:  # charge nested time to the inner category only
                self.seconds[self._stack[-1]] -= elapsed


class CpuMeter:
    """Process CPU time over wall time, in percent of one core (000 Table 6's load)."""

    def __init__(self) -> None:
        self._process = psutil.Process()
        self._cpu0 = self._cpu()
        self._wall0 = time.perf_counter()

    def _cpu(self) -> float:
        times = self._process.cpu_times()
        return times.user + times.system

    def load_pct(self) -> float:
        wall = time.perf_counter() - self._wall0
        return 100.0 * (self._cpu() - self._cpu0) / wall if wall > 0 else 0.0

    @property
    def wall_s(self) -> float:
        return time.perf_counter() - self._wall0


@dataclass
class TargetCoverage:
    """What the inspection of one target saw."""

    faces: set[int] = field(default_factory=set)
    low: NDArray[np.float64] = field(default_factory=lambda: np.full(3, np.inf))
    high: NDArray[np.float64] = field(default_factory=lambda: np.full(3, -np.inf))

    def add_points(self, points: NDArray[np.float64]) -> None:
        if len(points):
            self.low = np.minimum(self.low, points.min(axis=0))
            self.high = np.maximum(self.high, points.max(axis=0))

    @property
    def box_volume(self) -> float:
        extent = self.high - self.low
        return float(np.prod(extent)) if np.all(np.isfinite(extent)) else 0.0


class CoverageRecorder:
    """Collects, per inspected target, the faces seen up close and the extent of its masks."""

    def __init__(self, d_view: float) -> None:
        self.max_range = VIEW_RANGE_FACTOR * d_view
        self.targets: dict[str, TargetCoverage] = defaultdict(TargetCoverage)

    def add_frame(self, target_id: str, frame: Frame, mask_points: NDArray[np.float64]) -> None:
        record = self.targets[target_id]
        close = (frame.face >= 0) & (frame.depth <= self.max_range)
        # Counting beats sorting a frame's faces: the ids are small and dense.
        record.faces.update(np.flatnonzero(np.bincount(frame.face[close])).tolist())
        record.add_points(mask_points)

    def surface_coverage(self, target_id: str, world: World, instance_id: int) -> float:
        """Share of the instance's outward surface seen up close while inspecting ``target_id``."""
        faces = np.flatnonzero(world.face_instance == instance_id)
        outward = faces[world.face_normals[faces, 2] >= -0.5]
        areas = world.mesh.area_faces[outward]
        if areas.sum() <= 0:
            return 0.0
        seen = np.isin(outward, np.fromiter(self.targets[target_id].faces, dtype=np.int64))
        return float(areas[seen].sum() / areas.sum())


@dataclass
class LevelEndings:
    """How many levels ended by scene similarity (eq 8) and by the safety cap."""

    similarity: int = 0
    cap: int = 0


@dataclass(frozen=True)
class QueryAnswer:
    """An operator query answered after the mission and driven by the robot."""

    query: str
    goal: str | None
    planning_time_s: float | None
    path_length_m: float | None
    reached: bool
    final_distance_m: float | None
    error: str | None = None


@dataclass(frozen=True)
class RunIdentity:
    """Which world, scenario and seed a run explored, and the detector that saw it."""

    name: str
    scenario: str | None
    seed: int
    detector: str = "truth"  # runs before the detector seam had only the simulator's labels


@dataclass(frozen=True)
class GraphFigures:
    """000 Table 3's columns: ``[nodes, edges]`` per layer, reconciliation, detection."""

    target: tuple[int, int]
    level: tuple[int, int]
    pose: tuple[int, int]
    feature: tuple[int, int]
    total: tuple[int, int]
    unified: tuple[int, int]
    reconciled_pct: float
    detected_pct: float
    inspected_pct: float
    avg_planning_time_ms: float | None


@dataclass(frozen=True)
class QualityFigures:
    """000 Table 6's columns: load, localisation error and inspection coverage."""

    cpu_load_pct: float
    planning_load_pct: float | None
    localisation_rmse_m: float | None
    localisation_rmse_3d_m: float | None
    surface_coverage_pct: float | None
    bbox_volume_m3: float
    true_bbox_volume_m3: float
    bbox_volume_ratio: float | None
    #: Surface coverage of each inspected target that matched a true object, by target id.
    surface_coverage_by_target_pct: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class TargetFigures:
    """The Target layer scored against the world's true objects."""

    true: int
    in_graph: int
    matched: int
    inspected: int
    false_targets: int
    unreachable: list[str]
    matches: list[Match]


@dataclass(frozen=True)
class MissionFigures:
    """The mission's own figures: time, distance, sensing, levels and planning."""

    sim_time_s: float
    wall_time_s: float
    real_time_factor: float | None
    distance_m: float
    frames: int
    lidar_scans: int
    collisions: int
    level_endings: LevelEndings
    hierarchical_queries: int
    local_plans: int
    local_planning_ms_mean: float | None
    planning_wall_s: float
    planning_time_charged: bool
    wall_time_by_category_s: dict[str, float]


@dataclass(frozen=True)
class MissionMetrics:
    """Every figure of a run, as ``metrics.json`` holds them (:meth:`to_json`)."""

    state: str
    stop_reason: str
    world: RunIdentity
    table3: GraphFigures
    table6: QualityFigures
    targets: TargetFigures
    mission: MissionFigures
    queries: list[QueryAnswer]

    def to_json(self) -> dict[str, Any]:
        """The ``metrics.json`` content: nested dicts under the field names."""
        return asdict(self)

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> MissionMetrics:
        """Read back what :meth:`to_json` wrote."""
        t3 = dict(data["table3"])
        for layer in ("target", "level", "pose", "feature", "total", "unified"):
            t3[layer] = tuple(t3[layer])
        targets = dict(data["targets"])
        targets["matches"] = [Match(**m) for m in targets["matches"]]
        mission = dict(data["mission"])
        mission["level_endings"] = LevelEndings(**mission["level_endings"])
        return cls(
            data["state"],
            data["stop_reason"],
            RunIdentity(**data["world"]),
            GraphFigures(**t3),
            QualityFigures(**data["table6"]),
            TargetFigures(**targets),
            MissionFigures(**mission),
            [QueryAnswer(**q) for q in data["queries"]],
        )
