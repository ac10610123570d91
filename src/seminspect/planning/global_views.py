"""Inspection regions and the global view plan of 002 Sec III-C (Fig 3).

An inspection region ``R`` is a flat 3D polygon drawn on the historical map ``M_H``. Its global
view plan ``Z`` follows Fig 3: the polygon is covered by a grid whose lines are one camera
footprint apart, less the required overlap (horizontal spacing ``2 tan(α/2) d_view (1 - γ_H)``,
vertical ``2 tan(β/2) d_view (1 - γ_V)``, the steps of eq (1) at ``d_view``); intersections
inside the polygon are kept and each is projected ``d_view`` along the polygon's normal, facing
the surface. Poses in collision on ``M_H`` are repaired (pushed away from the surface, then up
or down) or dropped (``UpdatePlan`` of Algorithm 1).

The camera looks horizontally (a quadruped's body camera, as in 002 Sec IV), so a region must
be wall-like: its normal at most 30 degrees from horizontal. The normal's sign is the side of
the polygon that is free space on ``M_H``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.polygons import polygon_contains
from seminspect.geometry.transforms import as_points
from seminspect.mapping.voxel import FREE, OCCUPIED, VoxelMap
from seminspect.planning.view_planner import ViewConstraints

#: Largest distance of a vertex from the region's plane [m].
PLANARITY_TOLERANCE = 0.05
#: Steepest allowed tilt of a region's normal from horizontal [deg].
MAX_NORMAL_TILT_DEG = 30.0
#: Repair offsets tried for a pose in collision: away from the surface, then up/down [m].
REPAIR_OUTWARD = (0.1, 0.2, 0.3, 0.4, 0.5)
REPAIR_VERTICAL = (0.2, -0.2, 0.4, -0.4)


@dataclass(frozen=True)
class InspectionRegion:
    """A flat polygon ``R = {v_i}`` (002 Sec III-B) with a name, validated on construction."""

    name: str
    vertices: NDArray[np.float64]

    def __post_init__(self) -> None:
        points = as_points(self.vertices, f"region {self.name!r} vertices")
        if len(points) < 3:
            raise InvalidInputError(f"region {self.name!r} needs >= 3 vertices, got {len(points)}")
        object.__setattr__(self, "vertices", points)
        centred = points - points.mean(axis=0)
        _, singular, axes = np.linalg.svd(centred)
        if singular[1] < 1e-6:
            raise InvalidInputError(f"region {self.name!r} has no area (collinear vertices)")
        off_plane = float(np.abs(centred @ axes[2]).max())
        if off_plane > PLANARITY_TOLERANCE:
            raise InvalidInputError(
                f"region {self.name!r} is not planar: a vertex is {off_plane:.3f} m off its "
                f"plane (tolerance {PLANARITY_TOLERANCE} m)"
            )
        tilt = math.degrees(math.asin(min(1.0, abs(float(axes[2][2])))))
        if tilt > MAX_NORMAL_TILT_DEG:
            raise InvalidInputError(
                f"region {self.name!r} faces {tilt:.0f} deg from horizontal; the camera looks "
                f"horizontally, so regions must be wall-like (<= {MAX_NORMAL_TILT_DEG:.0f} deg)"
            )

    @property
    def centroid(self) -> NDArray[np.float64]:
        return self.vertices.mean(axis=0)

    def frame(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Unit ``u`` (horizontal, in the plane), ``v`` (up the plane) and normal ``n``
        (sign arbitrary; see :func:`outward_normal`)."""
        _, _, axes = np.linalg.svd(self.vertices - self.centroid)
        normal = axes[2].copy()
        normal[2] = 0.0  # the horizontal part fixes u; v then lies in the plane
        u = np.cross([0.0, 0.0, 1.0], normal / np.linalg.norm(normal))
        u /= np.linalg.norm(u)
        n = axes[2] / np.linalg.norm(axes[2])
        v = np.cross(n, u)
        if v[2] < 0:
            v, u = -v, -u
        return u, v, n

    def plane_coordinates(self, points: ArrayLike) -> NDArray[np.float64]:
        """``(K, 2)`` coordinates along ``u`` and ``v`` of points relative to the centroid."""
        u, v, _ = self.frame()
        offset = np.asarray(points, dtype=np.float64).reshape(-1, 3) - self.centroid
        return np.column_stack([offset @ u, offset @ v])

    def contains(self, points: ArrayLike, slab: float) -> NDArray[np.bool_]:
        """Points within the polygon's outline and ``slab`` metres of its plane."""
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        _, _, n = self.frame()
        near = np.abs((pts - self.centroid) @ n) <= slab
        inside = polygon_contains(
            self.plane_coordinates(self.vertices), self.plane_coordinates(pts)
        )
        return near & inside


@dataclass(frozen=True)
class ViewPlan:
    """``Z`` for one region: positions ``(K, 3)``, yaws ``(K,)``, the surface points they look
    at ``(K, 3)``, and how many grid poses were repaired or dropped for collisions on ``M_H``."""

    region: InspectionRegion
    positions: NDArray[np.float64]
    yaws: NDArray[np.float64]
    surface_points: NDArray[np.float64]
    normal: NDArray[np.float64]
    repaired: int
    dropped: int


def grid_spacing(constraints: ViewConstraints) -> tuple[float, float]:
    """Horizontal and vertical distance between grid lines (Fig 3(b))."""
    return constraints.horizontal_step, constraints.vertical_step


def grid_points(region: InspectionRegion, constraints: ViewConstraints) -> NDArray[np.float64]:
    """Grid intersections inside the polygon (Fig 3(c, left)), as 3D points on its plane.

    Grid lines are centred on the polygon's extent; a polygon narrower than one spacing gets
    one line through its middle. With no intersection inside, the centroid is used.
    """
    du, dv = grid_spacing(constraints)
    outline = region.plane_coordinates(region.vertices)
    axes = [
        _centred_lines(outline[:, i].min(), outline[:, i].max(), d) for i, d in ((0, du), (1, dv))
    ]
    uu, vv = np.meshgrid(*axes, indexing="ij")
    candidates = np.column_stack([uu.ravel(), vv.ravel()])
    kept = candidates[polygon_contains(outline, candidates)]
    if not len(kept):
        return region.centroid[None, :]
    u, v, _ = region.frame()
    return region.centroid + kept[:, :1] * u + kept[:, 1:] * v


def _centred_lines(low: float, high: float, spacing: float) -> NDArray[np.float64]:
    count = math.floor((high - low) / spacing) + 1
    middle = 0.5 * (low + high)
    return middle + spacing * (np.arange(count, dtype=np.float64) - (count - 1) / 2)


def outward_normal(
    region: InspectionRegion, prior: VoxelMap, d_view: float, viewer: ArrayLike
) -> NDArray[np.float64]:
    """The normal pointing into free space on ``M_H``: the side with more free than occupied
    cells along the normal between 0.3 m and ``d_view`` from the centroid; on a tie (a map
    without free space, such as a point cloud) the side facing ``viewer``."""
    _, _, n = region.frame()
    probes = np.linspace(0.3, d_view, 8)[:, None]

    def openness(direction: NDArray[np.float64]) -> int:
        states = prior.state_at(region.centroid + probes * direction)
        return int((states == FREE).sum()) - int((states == OCCUPIED).sum())

    ahead, behind = openness(n), openness(-n)
    if ahead == behind:
        return n if float((np.asarray(viewer) - region.centroid) @ n) >= 0 else -n
    return n if ahead > behind else -n


def pose_is_clear(prior: VoxelMap, point: NDArray[np.float64], radius: float) -> bool:
    """No occupied cell of ``prior`` within ``radius`` of ``point`` (cells outside count as
    clear: the map did not see them)."""
    step = prior.resolution
    reach = np.arange(-radius, radius + 1e-9, step)
    offsets = np.stack(np.meshgrid(reach, reach, reach, indexing="ij"), axis=-1).reshape(-1, 3)
    offsets = offsets[np.linalg.norm(offsets, axis=1) <= radius]
    return not bool((prior.state_at(point + offsets, outside=FREE) == OCCUPIED).any())


def global_view_plan(
    region: InspectionRegion,
    prior: VoxelMap,
    constraints: ViewConstraints,
    *,
    robot_radius: float,
    height_limits: tuple[float, float],
    viewer: ArrayLike,
) -> ViewPlan:
    """``GenerateGlobalViewPlan`` and ``UpdatePlan`` of Algorithm 1 for one region (Fig 3);
    ``viewer`` (the robot's start) breaks ties in :func:`outward_normal`."""
    normal = outward_normal(region, prior, constraints.d_view, viewer)
    horizontal = normal.copy()
    horizontal[2] = 0.0
    horizontal /= np.linalg.norm(horizontal)
    surface = grid_points(region, constraints)
    positions, yaws, seen, repaired, dropped = [], [], [], 0, 0
    low, high = height_limits
    for point in surface:
        pose = point + horizontal * constraints.d_view
        pose[2] = min(max(pose[2], low), high)
        fixed = _repair(prior, pose, horizontal, robot_radius, (low, high))
        if fixed is None:
            dropped += 1
            continue
        repaired += int(not np.array_equal(fixed, pose))
        positions.append(fixed)
        yaws.append(math.atan2(-horizontal[1], -horizontal[0]))
        seen.append(point)
    return ViewPlan(
        region,
        np.array(positions).reshape(-1, 3),
        np.array(yaws),
        np.array(seen).reshape(-1, 3),
        horizontal,
        repaired,
        dropped,
    )


def _repair(
    prior: VoxelMap,
    pose: NDArray[np.float64],
    outward: NDArray[np.float64],
    radius: float,
    limits: tuple[float, float],
) -> NDArray[np.float64] | None:
    """The pose, or the first clear one of the repair offsets; None if none is clear."""
    candidates = [pose]
    candidates += [pose + outward * d for d in REPAIR_OUTWARD]
    candidates += [pose + np.array([0.0, 0.0, dz]) for dz in REPAIR_VERTICAL]
    for candidate in candidates:
        if limits[0] <= candidate[2] <= limits[1] and pose_is_clear(prior, candidate, radius):
            return candidate
    return None
