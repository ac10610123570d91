"""Thinned free-space carving: near the sensor, only a subset of the rays frees cells.

The rays of one camera frame or LiDAR scan fan out from one point on a regular angular grid:
at distance ``d`` two neighbouring rays, an angle ``delta`` apart, are ``d * delta`` apart. Near
the sensor many rays cross the same cells, and the exact walk frees them again and again (a
VLP-16's 0.2 deg columns are one 0.2 m cell apart only beyond 57 m).

Thinning gives each ray a level: level ``L`` holds every ``2**L``-th ray of the grid (ray index
divisible by ``2**L``; :data:`MAX_LEVEL` and index 0 at the top). A ray of level ``L`` starts
freeing cells at the distance beyond which the rays of level ``L + 1`` are more than
``spacing`` cells apart, ``spacing * resolution / (2**(L + 1) * delta)``; top-level rays free
from the sensor. So at every distance the rays that free cells are fewer than ``spacing``
cells apart across the fan, and each ray still walks its far part, where the rays have spread.
End cells are untouched by thinning: every hit still occupies its cell and every ray's end
cell is still freed or occupied.

This is an approximation, never the default: a few cells that the exact walk frees stay
unknown (``tests/mapping/test_carving.py`` bounds their share), which only makes the map more
cautious. The mission's ``map_carving_spacing`` option turns it on.
"""

from __future__ import annotations

from functools import cache

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError

#: Every ``2**MAX_LEVEL``-th ray frees cells all the way from the sensor.
MAX_LEVEL = 6
#: :func:`median_step` looks at every this-many-th pair of consecutive rays.
STEP_SAMPLE = 8


@cache
def order_levels(count: int) -> NDArray[np.int64]:
    """:func:`index_levels` of ``0 .. count - 1`` (rays thinned by the order they come in),
    kept per count: a LiDAR's scans keep coming with the same few lengths."""
    levels = index_levels(np.arange(count))
    levels.flags.writeable = False
    return levels


def index_levels(index: NDArray[np.integer]) -> NDArray[np.int64]:
    """The thinning level of each ray from its index along the grid: the number of trailing
    zero bits, capped at :data:`MAX_LEVEL` (index 0 is at the top)."""
    values = np.abs(np.asarray(index, dtype=np.int64))
    lowest_bit = values & -values
    levels = np.full(values.shape, MAX_LEVEL, dtype=np.int64)
    nonzero = lowest_bit > 0
    levels[nonzero] = np.minimum(np.log2(lowest_bit[nonzero]).astype(np.int64), MAX_LEVEL)
    return levels


def carve_from(
    levels: NDArray[np.int64],
    lengths: NDArray[np.floating],
    angular_step: float,
    resolution: float,
    spacing: float,
) -> NDArray[np.float64]:
    """The fraction of each ray before which it frees no cells.

    Args:
        levels: ``(N,)`` thinning level per ray (:func:`index_levels`).
        lengths: ``(N,)`` ray lengths (metres).
        angular_step: angle between neighbouring rays of the grid (radians).
        resolution: the map's cell size (metres).
        spacing: the largest gap between freeing rays, in cells.
    """
    if not (np.isfinite(spacing) and spacing > 0):
        raise InvalidInputError(f"carving spacing must be > 0 cells, got {spacing}")
    if not (np.isfinite(angular_step) and angular_step > 0):
        raise InvalidInputError(f"angular step between rays must be > 0, got {angular_step}")
    start = spacing * resolution / (angular_step * np.exp2(levels + 1.0))
    start[levels >= MAX_LEVEL] = 0.0
    length = np.asarray(lengths, dtype=np.float64)
    return np.minimum(start / np.maximum(length, 1e-12), 1.0)


def median_step(rays: NDArray[np.floating], lengths: NDArray[np.floating]) -> float:
    """The median angle between consecutive rays (radians; ``rays`` of ``lengths``): the
    grid's step along the order in which a sensor lists its rays (a LiDAR's columns within
    each ring). The median is taken of the cosines, a monotonic stand-in for the angles, of
    every :data:`STEP_SAMPLE`-th pair: plenty for a median, and a scan has tens of thousands."""
    if len(rays) < 2:
        return float("inf")
    first, second = slice(0, -1, STEP_SAMPLE), slice(1, None, STEP_SAMPLE)
    dots = np.einsum("ij,ij->i", rays[first], rays[second])
    cosine = dots / (lengths[first] * lengths[second])
    return float(np.arccos(np.clip(np.median(cosine), -1.0, 1.0)))
