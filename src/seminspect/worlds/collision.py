"""Fast, conservative clearance queries from precomputed distance grids.

Two grids are built lazily from the world mesh, each on first use:

* ``ground``: a top-down grid (default 0.05 m) of everything a legged ground robot can neither
  step over nor walk under: non-ground surfaces between ``band[0]`` and ``band[1]`` metres above
  the ground. Clearance is the horizontal distance to that footprint; the point's height is
  ignored.
* ``aerial``: a 3D grid of every surface including the ground, at the finest of 0.1, 0.15, 0.2,
  ... m that keeps the grid under ``MAX_SPACE_CELLS`` cells.

A cell is occupied when a triangle touches it or when it lies inside an object (each object's
cells are hole-filled on their own, so a car or a building is solid while the open space between
tunnel walls or inside a room stays free). The Euclidean distance transform gives the distance
``D`` between cell centres; for a point in cell ``c`` the true distance to the nearest solid lies
within ``D(c) - r*sqrt(d)`` and ``D(c) + r*sqrt(d)`` (grid resolution ``r``, dimension ``d``).
:meth:`CollisionField.clearance` returns the lower bound, so ``is_free`` never accepts a point
closer than ``radius`` to a surface; it underestimates by at most ``2*r*sqrt(d)``: 0.14 m in the
0.05 m ground grid, 0.35 m in a 0.1 m aerial grid and 0.69 m in the city's 0.2 m aerial grid.

Each grid's distances are kept in the on-disk cache (``core.cache``) under a hash of the mesh,
the grid's parameters and this module's code: the next mission on the same world reads them
back instead of spending seconds on the rasterisation and the distance transform.

A world too large for its grids (more than :data:`MAX_GRID_CELLS` cells: a user world loaded at
the wrong scale) is refused from its extent alone, before anything is allocated
(:func:`check_grid_sizes`).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from typing import Literal

import numpy as np
import scipy
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

from seminspect.core.cache import array_key, cached_array, source_digest
from seminspect.core.errors import InvalidInputError
from seminspect.geometry import raster
from seminspect.geometry.transforms import as_point, as_points

CollisionMode = Literal["ground", "aerial"]
COLLISION_MODES: tuple[str, ...] = ("ground", "aerial")

#: Cap on the 3D grid: a 0.2 m grid of the 150 m x 100 m x 5 m city has 9.4 M cells and takes
#: about 2 s and 0.5 GB to build (scipy's distance transform keeps indices per cell).
MAX_SPACE_CELLS = 12_000_000
SPACE_RESOLUTIONS = (0.1, 0.15, 0.2, 0.25, 0.3, 0.4, 0.5, 0.75, 1.0)
#: Refuse a grid of more cells than this before allocating it: 17x the largest built-in grid
#: (the city's 0.05 m ground grid has 6 M cells, every aerial grid at most 12 M), a 0.05 m ground
#: grid about 700 m across, and 7-10 GB of memory to build (:data:`BUILD_BYTES_PER_CELL`).
MAX_GRID_CELLS = 200_000_000
#: Peak memory of building a grid, per cell: the distance transform's indices and float64
#: distances (measured with scipy 1.17: 33 bytes a cell in 2D, 49 in 3D).
BUILD_BYTES_PER_CELL = 50


@dataclass(frozen=True)
class DistanceGrid:
    """Distances (metres, ``float32``) from cell centres to the nearest occupied cell."""

    origin: NDArray[np.float64]
    resolution: float
    distance: NDArray[np.float32]

    @property
    def slack(self) -> float:
        """``r*sqrt(d)``: the most a cell-centre distance can exceed the true one.

        :meth:`lower_bound` subtracts it, and so underestimates by at most twice this.
        """
        return self.resolution * math.sqrt(self.distance.ndim)

    def lower_bound(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """Conservative distance to the nearest surface; 0 outside the grid."""
        dims = self.distance.ndim
        idx = np.floor((points[:, :dims] - self.origin[:dims]) / self.resolution).astype(np.int64)
        inside = np.all((idx >= 0) & (idx < np.asarray(self.distance.shape)), axis=1)
        result = np.zeros(len(points))
        hit = idx[inside]
        values = self.distance[tuple(hit.T)]
        result[inside] = np.maximum(values - self.slack, 0.0)
        return result


@dataclass(frozen=True)
class Sweep:
    """How far (fraction 0..1 of the segment) a body got, and where it first touched."""

    free_until: float
    contact: float | None


def _solid_cells(
    triangles: NDArray[np.float64],
    face_instance: NDArray[np.int32],
    origin: NDArray[np.float64],
    cell: NDArray[np.float64],
    shape: tuple[int, ...],
) -> NDArray[np.bool_]:
    """Cells touching a triangle, plus the enclosed inside of every object (instance > 0)."""
    nx, ny, nz = shape  # a 3D grid
    occupied = raster.cells_touching_triangles(
        triangles[face_instance == 0], origin, cell, (nx, ny, nz)
    )
    order = np.argsort(face_instance, kind="stable")
    ids, starts = np.unique(face_instance[order], return_index=True)
    for inst, lo, hi in zip(ids, starts, np.append(starts[1:], len(order)), strict=True):
        if inst == 0:
            continue
        own = triangles[order[lo:hi]]
        first = np.floor((own.min(axis=(0, 1)) - origin) / cell).astype(int) - 1
        last = np.floor((own.max(axis=(0, 1)) - origin) / cell).astype(int) + 2
        first, last = np.maximum(first, 0), np.minimum(last, shape)
        if np.any(last <= first):
            continue
        local = raster.cells_touching_triangles(
            own, origin + first * cell, cell, tuple(last - first)
        )
        window = tuple(slice(a, b) for a, b in zip(first, last, strict=True))
        occupied[window] |= ndimage.binary_fill_holes(local)
    return occupied


def _distances(occupied: NDArray[np.bool_], resolution: float) -> NDArray[np.float32]:
    if occupied.any():
        distance = ndimage.distance_transform_edt(~occupied, sampling=resolution)
    else:  # nothing to hit: every cell is as far as the grid is wide
        distance = np.full(occupied.shape, resolution * max(occupied.shape))
    return distance.astype(np.float32)


def check_grid_sizes(
    bounds: NDArray[np.float64],
    ground_resolution: float = 0.05,
    aerial_resolution: float | None = None,
    fix: str = "use smaller bounds or a coarser grid resolution",
) -> None:
    """Refuse ``bounds`` whose ground or aerial grid would exceed :data:`MAX_GRID_CELLS`, from
    its extent alone, before anything is allocated; ``fix`` ends the message."""
    box = np.asarray(bounds, dtype=np.float64)
    extent = box[1] - box[0]
    size = " x ".join(f"{e:.4g}" for e in extent)
    if not np.all(np.isfinite(extent)):
        raise InvalidInputError(f"the world's extent ({size} m) is not finite; {fix}")
    resolutions = (ground_resolution, aerial_resolution or space_resolution(box))
    for mode, resolution, axes in zip(COLLISION_MODES, resolutions, (2, 3), strict=True):
        cells = float(np.prod(np.maximum(np.ceil(extent[:axes] / resolution), 1.0)))
        if cells > MAX_GRID_CELLS:
            gigabytes = cells * BUILD_BYTES_PER_CELL / 1e9
            raise InvalidInputError(
                f"the world is {size} m: its {mode} collision grid would have {cells:.3g} cells "
                f"at {resolution:g} m (about {gigabytes:.3g} GB to build), more than the "
                f"{MAX_GRID_CELLS:.3g} cells seminspect builds (a ground grid about 700 m across); "
                f"{fix}"
            )


def space_resolution(bounds: NDArray[np.float64], max_cells: int = MAX_SPACE_CELLS) -> float:
    """Finest resolution of :data:`SPACE_RESOLUTIONS` whose grid over ``bounds`` fits."""
    extent = bounds[1] - bounds[0]
    for resolution in SPACE_RESOLUTIONS:
        if math.prod(math.ceil(e / resolution) for e in extent) <= max_cells:
            return resolution
    return SPACE_RESOLUTIONS[-1]


class CollisionField:
    """Clearance, free-point and free-segment queries for ground and aerial robots.

    Args:
        triangles: ``(F, 3, 3)`` world triangles.
        face_instance: ``(F,)`` object of each face (0: background, never hole-filled).
        is_ground: ``(F,)`` True for ground faces (ignored by the ground-robot grid).
        bounds: ``(2, 3)`` world box; everything outside it counts as blocked.
        ground_z: height of the ground the ground-robot band is measured from.
        band: heights above ``ground_z`` between which surfaces block a ground robot.
        ground_resolution: cell size of the ground-robot grid.
        aerial_resolution: cell size of the 3D grid (``None``: see :func:`space_resolution`).
    """

    def __init__(
        self,
        triangles: NDArray[np.float64],
        face_instance: NDArray[np.int32],
        is_ground: NDArray[np.bool_],
        bounds: NDArray[np.float64],
        *,
        ground_z: float,
        band: tuple[float, float] = (0.15, 2.0),
        ground_resolution: float = 0.05,
        aerial_resolution: float | None = None,
    ) -> None:
        if not (0.0 <= band[0] < band[1]):
            raise InvalidInputError(f"ground band must satisfy 0 <= low < high, got {band}")
        check_grid_sizes(bounds, ground_resolution, aerial_resolution)
        self._triangles = triangles
        self._face_instance = face_instance
        self._is_ground = is_ground
        self.bounds = np.asarray(bounds, dtype=np.float64)
        self.ground_z = float(ground_z)
        self.band = band
        self.ground_resolution = float(ground_resolution)
        self.aerial_resolution = float(aerial_resolution or space_resolution(self.bounds))

    @cached_property
    def ground(self) -> DistanceGrid:
        """Top-down distance grid of obstacles inside the ground robot's height band."""
        res = self.ground_resolution
        low, high = self.ground_z + self.band[0], self.ground_z + self.band[1]
        origin = np.array([self.bounds[0, 0], self.bounds[0, 1], low])
        shape = (*_cells(self.bounds[:, :2], res), 1)
        keep = ~self._is_ground

        def build() -> NDArray[np.float32]:
            occupied = _solid_cells(
                self._triangles[keep],
                self._face_instance[keep],
                origin,
                np.array([res, res, high - low]),
                shape,
            )
            return _distances(occupied[:, :, 0], res)

        return DistanceGrid(origin, res, self._cached("ground", build, keep, origin, shape))

    @cached_property
    def aerial(self) -> DistanceGrid:
        """3D distance grid of every surface, ground included."""
        res = self.aerial_resolution
        origin = self.bounds[0].copy()
        shape = _cells(self.bounds, res)
        cell = np.full(3, res)

        def build() -> NDArray[np.float32]:
            occupied = _solid_cells(self._triangles, self._face_instance, origin, cell, shape)
            return _distances(occupied, res)

        return DistanceGrid(origin, res, self._cached("aerial", build, origin, shape))

    def _cached(
        self, mode: CollisionMode, build: Callable[[], NDArray[np.float32]], *inputs: object
    ) -> NDArray[np.float32]:
        """``build()``'s distances, from the on-disk cache when this mesh's grid is there.

        The key holds the mesh, the grid's parameters and the source of the code that builds
        it, so any change to them builds afresh (``core.cache``).
        """
        key = array_key(
            mode,
            self._triangles,
            self._face_instance,
            self.bounds,
            self.ground_z,
            self.band,
            *inputs,
            source_digest(sys.modules[__name__], raster),
            scipy.__version__,
        )
        return cached_array("collision", key, build)

    def grid(self, mode: CollisionMode) -> DistanceGrid:
        if mode == "ground":
            return self.ground
        if mode == "aerial":
            return self.aerial
        raise InvalidInputError(f"collision mode must be one of {COLLISION_MODES}, got {mode!r}")

    def clearance(self, points: ArrayLike, mode: CollisionMode = "aerial") -> NDArray[np.float64]:
        """Lower bound of each point's distance to the nearest surface (0 outside the world)."""
        pts = as_points(points, "clearance query points", allow_empty=True)
        distance = self.grid(mode).lower_bound(pts)
        if mode == "aerial":
            outside = np.any((pts < self.bounds[0]) | (pts > self.bounds[1]), axis=1)
            distance[outside] = 0.0
        return distance

    def is_free(
        self, points: ArrayLike, radius: float, mode: CollisionMode = "aerial"
    ) -> NDArray[np.bool_]:
        """Whether a sphere (aerial) or disc (ground) of ``radius`` fits at each point."""
        return self.clearance(points, mode) >= _radius(radius)

    def sweep(
        self, start: ArrayLike, end: ArrayLike, radius: float, mode: CollisionMode = "aerial"
    ) -> Sweep:
        """Move a body of ``radius`` along ``start -> end`` and report its first contact.

        The segment is sampled every half grid cell.
        """
        a, b = as_point(start, "segment start"), as_point(end, "segment end")
        samples = _segment_samples(a, b, 0.5 * self.grid(mode).resolution)
        free = self.is_free(a + np.outer(samples, b - a), radius, mode)
        if free.all():
            return Sweep(1.0, None)
        first = int(np.argmin(free))
        return Sweep(float(samples[first - 1]) if first else 0.0, float(samples[first]))

    def segment_is_free(
        self, start: ArrayLike, end: ArrayLike, radius: float, mode: CollisionMode = "aerial"
    ) -> bool:
        """Whether the body can sweep the straight segment without touching a surface."""
        return self.sweep(start, end, radius, mode).contact is None


def _cells(bounds: NDArray[np.float64], resolution: float) -> tuple[int, ...]:
    return tuple(max(1, math.ceil(e / resolution - 1e-9)) for e in bounds[1] - bounds[0])


def _radius(radius: float) -> float:
    if not (math.isfinite(radius) and radius >= 0):
        raise InvalidInputError(f"radius must be finite and >= 0, got {radius}")
    return float(radius)


def _segment_samples(a: NDArray, b: NDArray, spacing: float) -> NDArray[np.float64]:
    """Fractions 0..1 along ``a -> b`` no farther apart than ``spacing`` metres."""
    count = max(1, math.ceil(float(np.linalg.norm(b - a)) / spacing))
    return np.linspace(0.0, 1.0, count + 1)
