"""Voxel occupancy maps: every cell is unknown, free or occupied.

The map is a dense ``uint8`` array over an axis-aligned box. Cell ``(i, j, k)`` covers
``origin + resolution * [i, i+1) x [j, j+1) x [k, k+1)``. Dense storage keeps lookups and the
compiled planners simple; a 150 m x 100 m x 5 m city at 0.2 m is 47 M cells (47 MB).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import as_point

UNKNOWN: int = 0
FREE: int = 1
OCCUPIED: int = 2

#: Refuse maps larger than this many cells (2 GiB of uint8) with a clear error.
MAX_CELLS = 2 << 30


@dataclass
class VoxelMap:
    """A dense occupancy grid.

    Attributes:
        origin: world coordinates of the grid's minimum corner (metres).
        resolution: edge length of a cell (metres).
        states: ``uint8`` array of shape ``(nx, ny, nz)`` holding UNKNOWN, FREE or OCCUPIED.
    """

    origin: NDArray[np.float64]
    resolution: float
    states: NDArray[np.uint8]

    def __post_init__(self) -> None:
        self.origin = as_point(self.origin, "voxel map origin")
        if not (math.isfinite(self.resolution) and self.resolution > 0):
            raise InvalidInputError(f"voxel resolution must be > 0, got {self.resolution}")
        self.resolution = float(self.resolution)
        if self.states.ndim != 3 or self.states.dtype != np.uint8:
            raise InvalidInputError("voxel states must be a 3D uint8 array")

    @classmethod
    def empty(cls, lower: ArrayLike, upper: ArrayLike, resolution: float) -> VoxelMap:
        """An all-unknown map covering the box ``[lower, upper]``."""
        lo = as_point(lower, "map lower corner")
        hi = as_point(upper, "map upper corner")
        if not (math.isfinite(resolution) and resolution > 0):
            raise InvalidInputError(f"voxel resolution must be > 0, got {resolution}")
        if np.any(hi <= lo):
            raise InvalidInputError(f"map box is empty: lower {lo.tolist()} upper {hi.tolist()}")
        shape = tuple(int(n) for n in np.ceil((hi - lo) / resolution - 1e-9))
        cells = math.prod(shape)
        if cells > MAX_CELLS:
            raise InvalidInputError(
                f"a {resolution} m map of this box needs {cells:,} cells; use a coarser resolution"
            )
        return cls(lo, resolution, np.zeros(shape, dtype=np.uint8))

    @property
    def shape(self) -> tuple[int, int, int]:
        return self.states.shape  # type: ignore[return-value]

    @property
    def upper(self) -> NDArray[np.float64]:
        """World coordinates of the grid's maximum corner."""
        return self.origin + self.resolution * np.asarray(self.shape, dtype=np.float64)

    def world_to_index(self, points: ArrayLike) -> NDArray[np.int64]:
        """Cell indices of world points (``(..., 3)``); cells outside the grid are not clipped."""
        pts = np.asarray(points, dtype=np.float64)
        return np.floor((pts - self.origin) / self.resolution).astype(np.int64)

    def index_to_world(self, indices: ArrayLike) -> NDArray[np.float64]:
        """World coordinates of cell centres."""
        idx = np.asarray(indices, dtype=np.float64)
        return self.origin + (idx + 0.5) * self.resolution

    def contains_index(self, indices: ArrayLike) -> NDArray[np.bool_]:
        """Whether each index lies inside the grid."""
        idx = np.asarray(indices)
        return np.all((idx >= 0) & (idx < np.asarray(self.shape)), axis=-1)

    def state_at(self, points: ArrayLike, outside: int = UNKNOWN) -> NDArray[np.uint8]:
        """States of the cells holding ``points``; points outside the grid read as ``outside``."""
        idx = self.world_to_index(points)
        inside = self.contains_index(idx)
        result = np.full(idx.shape[:-1], outside, dtype=np.uint8)
        hit = idx[inside]
        result[inside] = self.states[hit[:, 0], hit[:, 1], hit[:, 2]]
        return result

    def counts(self) -> dict[str, int]:
        """Number of unknown, free and occupied cells."""
        tally = np.bincount(self.states.ravel(), minlength=3)
        return {
            "unknown": int(tally[UNKNOWN]),
            "free": int(tally[FREE]),
            "occupied": int(tally[OCCUPIED]),
        }
