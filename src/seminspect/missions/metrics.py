"""Mission measurements: where wall time goes, CPU load and inspection coverage (000 Table 6).

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
from dataclasses import dataclass, field

import numpy as np
import psutil
from numpy.typing import NDArray

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
        record.faces.update(np.unique(frame.face[close]).tolist())
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
