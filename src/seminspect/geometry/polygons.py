"""Simple polygons from ordered points (the containment polygons of 000 Sec V-B)."""

from __future__ import annotations

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray

#: Points closer than this are the same vertex.
_VERTEX_TOLERANCE = 1e-6


#: Points on the arc of a sector tested by :func:`polygon_meets_sector`.
SECTOR_ARC_POINTS = 17


def _drop_repeats(points: NDArray[np.float64]) -> NDArray[np.float64]:
    keep = [0]
    for i in range(1, len(points)):
        if np.linalg.norm(points[i] - points[keep[-1]]) > _VERTEX_TOLERANCE:
            keep.append(i)
    if len(keep) > 1 and np.linalg.norm(points[keep[-1]] - points[keep[0]]) <= _VERTEX_TOLERANCE:
        keep.pop()
    return points[keep]


def ring_polygon(points_xy: ArrayLike) -> NDArray[np.float64] | None:
    """A simple polygon whose vertices are ``points_xy`` (K x 2).

    The points are used in the order given when that ring is simple (no self-intersection).
    Otherwise, e.g. when a noisy pose track crosses itself, the convex hull of the points is used;
    its vertices are still a subset of the points. Returns ``None`` when fewer than three distinct
    points remain or they are collinear (no area).
    """
    pts = np.asarray(points_xy, dtype=np.float64).reshape(-1, 2)
    if len(pts) == 0:
        return None
    pts = _drop_repeats(pts)
    if len(pts) < 3:
        return None
    ring = shapely.Polygon(pts)
    if ring.is_valid and ring.area > 0:
        return pts
    return hull_polygon(pts)


def hull_polygon(points_xy: ArrayLike) -> NDArray[np.float64] | None:
    """The convex hull of ``points_xy`` (K x 2) as polygon vertices, or ``None`` when it has
    no area (fewer than three points, or all on a line)."""
    pts = np.asarray(points_xy, dtype=np.float64).reshape(-1, 2)
    hull = shapely.MultiPoint(pts).convex_hull
    if isinstance(hull, shapely.Polygon) and hull.area > 0:
        return np.asarray(hull.exterior.coords, dtype=np.float64)[:-1]
    return None


def polygon_centroid(vertices: ArrayLike) -> NDArray[np.float64]:
    """Area centroid of a simple polygon (K x 2)."""
    centroid = shapely.Polygon(np.asarray(vertices, dtype=np.float64)).centroid
    return np.array([centroid.x, centroid.y])


def polygon_contains(vertices: ArrayLike, points_xy: ArrayLike) -> NDArray[np.bool_]:
    """Point-in-polygon test ``P`` of 000 eq (4) for each point (boundary counts as outside)."""
    polygon = shapely.Polygon(np.asarray(vertices, dtype=np.float64))
    pts = np.asarray(points_xy, dtype=np.float64).reshape(-1, 2)
    return shapely.contains_xy(polygon, pts[:, 0], pts[:, 1])


def polygon_meets_sector(
    vertices: ArrayLike, apex: ArrayLike, heading: float, half_angle: float, radius: float
) -> bool:
    """Whether a polygon (K x 2) overlaps the circular sector seen from ``apex`` (x, y, ...)
    along ``heading`` within ``half_angle`` either side, out to ``radius`` [m, rad]."""
    x, y = np.asarray(apex, dtype=np.float64)[:2]
    angles = heading + np.linspace(-half_angle, half_angle, SECTOR_ARC_POINTS)
    arc = np.column_stack([x + radius * np.cos(angles), y + radius * np.sin(angles)])
    sector = shapely.Polygon(np.vstack([[x, y], arc]))
    return bool(sector.intersects(shapely.Polygon(np.asarray(vertices, dtype=np.float64))))
