"""Frontier-based volumetric exploration on the robot's own map, with no semantic targets.

This is the role GBPlanner2.0 plays in 000 Table 6 (000 Sec VII-D, baseline (ii)): a planner
that only maps unknown space. Frontiers are free cells of the robot's height band that touch
unknown ones (Yamauchi's frontiers), grouped into 8-connected clusters. Each cluster is scored
by the receding-horizon next-best-view utility of 000 ref [24] (Bircher et al.),
``gain * exp(-lambda * cost)``: the gain is the unknown area of the band within
``gain_radius`` of the cluster's goal, the cost the straight-line distance from the robot to it.

Readings chosen here, not given by the papers: the gain is counted on the planar band a ground
robot drives in (what its planners see), not over full 3D rays; the cost is the straight-line
distance, since a route per candidate would cost more planning than the choice is worth (the
chosen goal is then reached by the mission's own planner, which replans as the map grows). The
choice is deterministic: ties go to the cluster found first in the map's index order.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

from seminspect.core.errors import InvalidInputError
from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap
from seminspect.planning.gridmap import planar_states


@dataclass(frozen=True)
class Frontier:
    """A boundary between known free and unknown space, at the robot's height."""

    goal: NDArray[np.float64]
    cells: int


def find_frontiers(
    occupancy: VoxelMap,
    band: tuple[float, float],
    min_cells: int,
    height: float,
    wall_clearance: float = 1.0,
) -> list[Frontier]:
    """Frontiers of the map's height band: free cells touching unknown ones, grouped.

    Free cells closer than ``wall_clearance`` to an obstacle are left out: along a wall the
    unknown side is the inside of a building, which no visit can reveal. Each group's goal is
    its cell closest to the group's mean, lifted to ``height``.
    """
    layer = planar_states(occupancy, band)[:, :, 0]
    free = layer == FREE
    touching = ndimage.binary_dilation(
        layer == UNKNOWN, structure=ndimage.generate_binary_structure(2, 1)
    )
    open_space = ndimage.distance_transform_edt(layer != OCCUPIED) * occupancy.resolution
    frontier = free & touching & (open_space > wall_clearance)
    labels, count = ndimage.label(frontier, structure=np.ones((3, 3), dtype=bool))
    if count == 0:
        return []
    sizes = np.bincount(labels.ravel())
    found = []
    for group in np.flatnonzero(sizes >= min_cells):
        if group == 0:
            continue
        cells = np.argwhere(labels == group)
        centre = cells.mean(axis=0)
        pick = cells[np.argmin(((cells - centre) ** 2).sum(axis=1))]
        xy = occupancy.origin[:2] + (pick + 0.5) * occupancy.resolution
        found.append(Frontier(np.array([xy[0], xy[1], height]), int(sizes[group])))
    return found


def unknown_area(
    occupancy: VoxelMap, band: tuple[float, float], goals: ArrayLike, radius: float
) -> NDArray[np.float64]:
    """Unknown area of the height band within ``radius`` of each goal [m^2]: the volumetric
    gain of a visit, counted on the band's projection.

    Args:
        goals: (n, 3) float, world points (only x and y are used).
    """
    unknown = planar_states(occupancy, band)[:, :, 0] == UNKNOWN
    res = occupancy.resolution
    reach = math.ceil(radius / res)
    offsets = np.arange(-reach, reach + 1)
    disk = (offsets[:, None] ** 2 + offsets[None, :] ** 2) * res**2 <= radius**2
    # Pad so that every window is whole: cells outside the map count as known (nothing to gain).
    padded = np.pad(unknown, reach, constant_values=False)
    centres = np.floor((np.asarray(goals, dtype=np.float64)[:, :2] - occupancy.origin[:2]) / res)
    on_map = np.all((centres >= 0) & (centres < occupancy.shape[:2]), axis=1)
    gains = np.zeros(len(centres))
    for k in np.flatnonzero(on_map):  # a goal off the map gains nothing
        i, j = centres[k].astype(np.int64)
        window = padded[i : i + 2 * reach + 1, j : j + 2 * reach + 1]
        gains[k] = np.count_nonzero(window & disk) * res**2
    return gains


@dataclass(frozen=True)
class ScoredFrontier:
    """A frontier with the terms of its utility."""

    frontier: Frontier
    gain_m2: float
    distance_m: float
    utility: float


@dataclass
class FrontierPlanner:
    """Chooses where to explore next: frontiers ranked by ``gain * exp(-lambda * distance)``.

    Args:
        gain_radius: how far around a goal unknown space counts as its gain [m].
        distance_penalty: ``lambda`` of 000 ref [24]'s utility [1/m]; 0.1 values a frontier
            with twice the unknown area 7 m farther away the same.
        min_distance: frontiers nearer than this to the robot, or to a goal already spent, are
            skipped: the ring around the robot's own body that no sensor sees is never resolved
            by a trip [m].
    """

    gain_radius: float = 10.0
    distance_penalty: float = 0.1
    min_distance: float = 3.0
    #: Goals visited or found unreachable; they are not chosen again.
    spent: list[NDArray[np.float64]] = field(default_factory=list)

    def __post_init__(self) -> None:
        for name in ("gain_radius", "distance_penalty", "min_distance"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise InvalidInputError(f"{name} must be finite and >= 0, got {value!r}")
        if self.gain_radius <= 0:
            raise InvalidInputError(f"gain_radius must be > 0, got {self.gain_radius!r}")

    def rank(
        self,
        occupancy: VoxelMap,
        band: tuple[float, float],
        position: ArrayLike,
        min_cells: int,
    ) -> list[ScoredFrontier]:
        """The map's frontiers worth a trip, best first; empty when none is left."""
        here = np.asarray(position, dtype=np.float64)
        frontiers = [
            f
            for f in find_frontiers(occupancy, band, min_cells, float(here[2]))
            if _planar_distance(f.goal, here) >= self.min_distance and not self.is_spent(f.goal)
        ]
        if not frontiers:
            return []
        goals = np.array([f.goal for f in frontiers])
        gains = unknown_area(occupancy, band, goals, self.gain_radius)
        scored = []
        for frontier, gain in zip(frontiers, gains, strict=True):
            distance = _planar_distance(frontier.goal, here)
            utility = float(gain) * math.exp(-self.distance_penalty * distance)
            scored.append(ScoredFrontier(frontier, float(gain), distance, utility))
        # Stable: equal utilities keep the map's index order, so the choice never depends on luck.
        return sorted(scored, key=lambda s: -s.utility)

    def mark_spent(self, goal: ArrayLike) -> None:
        """Remember a goal visited or found unreachable."""
        self.spent.append(np.asarray(goal, dtype=np.float64))

    def is_spent(self, goal: ArrayLike) -> bool:
        """Whether a goal near ``goal`` was visited or tried already."""
        point = np.asarray(goal, dtype=np.float64)
        return any(_planar_distance(point, s) < self.min_distance for s in self.spent)


def _planar_distance(a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    return float(np.linalg.norm((a - b)[:2]))
