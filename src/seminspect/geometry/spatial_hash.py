"""A uniform-grid spatial hash for "is anything within r of this point?" under insertion."""

from __future__ import annotations

import itertools
import math
from typing import Generic, TypeVar

import numpy as np
from numpy.typing import ArrayLike

from seminspect.core.errors import InvalidInputError

T = TypeVar("T")
_NEIGHBOURHOOD = tuple(itertools.product((-1, 0, 1), repeat=3))


class PointHash(Generic[T]):
    """Points with payloads, bucketed in cubes of edge ``cell``.

    Radius queries with ``radius <= cell`` look at the 27 surrounding buckets only, so lookups
    stay constant-time however many points are stored.
    """

    def __init__(self, cell: float) -> None:
        if not (math.isfinite(cell) and cell > 0):
            raise InvalidInputError(f"hash cell size must be > 0, got {cell}")
        self.cell = float(cell)
        self._buckets: dict[tuple[int, int, int], list[tuple[np.ndarray, T]]] = {}

    def _key(self, point: np.ndarray) -> tuple[int, int, int]:
        return (
            math.floor(point[0] / self.cell),
            math.floor(point[1] / self.cell),
            math.floor(point[2] / self.cell),
        )

    def add(self, point: ArrayLike, payload: T) -> None:
        p = np.asarray(point, dtype=np.float64)
        self._buckets.setdefault(self._key(p), []).append((p, payload))

    def nearest_within(self, point: ArrayLike, radius: float) -> tuple[T, float] | None:
        """The nearest stored payload within ``radius`` (ties: earliest added), or None."""
        if radius > self.cell:
            raise InvalidInputError(f"radius {radius} exceeds the hash cell {self.cell}")
        p = np.asarray(point, dtype=np.float64)
        kx, ky, kz = self._key(p)
        best: tuple[T, float] | None = None
        for dx, dy, dz in _NEIGHBOURHOOD:
            for q, payload in self._buckets.get((kx + dx, ky + dy, kz + dz), ()):
                d = math.dist(p, q)
                if d <= radius and (best is None or d < best[1]):
                    best = (payload, d)
        return best
