"""Voxel occupancy maps: every cell is unknown, free or occupied.

The map is a dense ``uint8`` array over an axis-aligned box. Cell ``(i, j, k)`` covers
``origin + resolution * [i, i+1) x [j, j+1) x [k, k+1)``. Dense storage keeps lookups and the
compiled planners simple; a 150 m x 100 m x 5 m city at 0.2 m is 47 M cells (47 MB).

Maps grow from sensor data (:meth:`VoxelMap.integrate_frame`, :meth:`VoxelMap.integrate_scan`,
both by compiled ray traversal, see ``mapping.traversal``) or are built straight from a world's
mesh for baselines (:meth:`VoxelMap.from_world`), as the occupancy map of 004 Sec III-A: a grid
of resolution r_V whose cells are occupied, free or unknown.
"""

from __future__ import annotations

import math
import os
from concurrent.futures import Future
from functools import lru_cache, partial
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage
from scipy.spatial.transform import Rotation

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import save_npz_atomic
from seminspect.core.threads import rotate_rows, sensor_threads, serial_worker
from seminspect.geometry.raster import cells_touching_triangles
from seminspect.geometry.transforms import as_point, as_points
from seminspect.mapping import carving
from seminspect.mapping.semantic_cloud import read_npz
from seminspect.mapping.traversal import integrate_rays_kernel
from seminspect.sensors import CameraModel, Frame, LidarScan
from seminspect.worlds import World

UNKNOWN: int = 0
FREE: int = 1
OCCUPIED: int = 2

#: Refuse maps larger than this many cells (2 GiB of uint8) with a clear error.
MAX_CELLS = 2 << 30
MAP_FORMAT = "seminspect.voxel-map"
MAP_VERSION = 1


class VoxelMap:
    """A dense occupancy grid.

    Attributes:
        origin: world coordinates of the grid's minimum corner (metres).
        resolution: edge length of a cell (metres).
        states: ``uint8`` array of shape ``(nx, ny, nz)`` holding UNKNOWN, FREE or OCCUPIED,
            kept C-ordered (a strided view is copied) so the ray walk can step through it flat.
        background: walk integrated rays on a worker thread
            (:func:`~seminspect.core.threads.serial_worker`) while the caller goes on. Reading or
            replacing :attr:`states` first waits for every walk handed over, and the walks run
            in the order they were handed over, so every read sees the cells the same
            integrations would have left in place. An array taken from :attr:`states` is the
            live grid: read it before integrating more, not across an integration. Either
            way a large batch of rays is dealt out to the sensors' threads
            (:func:`~seminspect.core.threads.sensor_threads`; the same map on any number).
    """

    def __init__(self, origin: ArrayLike, resolution: float, states: NDArray[np.uint8]) -> None:
        self.origin = as_point(origin, "voxel map origin")
        if not (math.isfinite(resolution) and resolution > 0):
            raise InvalidInputError(f"voxel resolution must be > 0, got {resolution}")
        self.resolution = float(resolution)
        self._pending: list[Future[None]] = []
        self.background = False
        self.states = states

    @property
    def states(self) -> NDArray[np.uint8]:
        """The cells, once every integration handed to the worker thread has finished."""
        self.settle()
        return self._cells

    @states.setter
    def states(self, cells: NDArray[np.uint8]) -> None:
        self.settle()
        if cells.ndim != 3 or cells.dtype != np.uint8:
            raise InvalidInputError("voxel states must be a 3D uint8 array")
        self._cells = np.ascontiguousarray(cells)

    def settle(self) -> None:
        """Wait for the rays handed to the worker thread to be walked into the map."""
        pending, self._pending = self._pending, []
        for walks in pending:
            walks.result()

    def __getstate__(self) -> dict[str, object]:
        """Pickled (e.g. by Ray) with its cells settled and without the pending work."""
        return {"origin": self.origin, "resolution": self.resolution, "cells": self.states}

    def __setstate__(self, state: dict[str, object]) -> None:
        VoxelMap.__init__(self, state["origin"], state["resolution"], state["cells"])  # type: ignore[arg-type]

    def __repr__(self) -> str:
        origin, shape = self.origin.tolist(), self.shape
        return f"VoxelMap(origin={origin}, resolution={self.resolution}, shape={shape})"

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
        return self._cells.shape  # type: ignore[return-value]

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

    # ----------------------------------------------------------------- building from data
    @classmethod
    def covering(cls, world: World, resolution: float) -> VoxelMap:
        """An all-unknown map of the world's bounds, lowered by half a cell.

        The ground then runs through the middle of the bottom layer instead of along the
        grid's lower face, where rounding would put half of the ground hits outside the map.
        """
        lower = world.bounds[0] - [0.0, 0.0, 0.5 * resolution]
        return cls.empty(lower, world.bounds[1], resolution)

    @classmethod
    def from_world(
        cls, world: World, resolution: float, bounds: ArrayLike | None = None
    ) -> VoxelMap:
        """The map of a perfectly known world: cells touching the mesh (ground included) are
        occupied, every other cell is free. The box defaults to :meth:`covering`'s.
        """
        if bounds is None:
            grid = cls.covering(world, resolution)
        else:
            box = np.asarray(bounds, dtype=np.float64)
            grid = cls.empty(box[0], box[1], resolution)
        occupied = cells_touching_triangles(world.triangles, grid.origin, resolution, grid.shape)
        grid.states[:] = np.where(occupied, OCCUPIED, FREE)
        return grid

    @classmethod
    def from_boxes(
        cls, lower: ArrayLike, upper: ArrayLike, resolution: float, boxes: ArrayLike
    ) -> VoxelMap:
        """A known map of the box ``[lower, upper]``: cells overlapping any of ``boxes``
        (``(B, 2, 3)``, lower and upper corners) are occupied, every other cell is free."""
        grid = cls.empty(lower, upper, resolution)
        grid.states[:] = FREE
        corners = np.asarray(boxes, dtype=np.float64).reshape(-1, 2, 3)
        if not np.all(np.isfinite(corners)):
            raise InvalidInputError("box corners must be finite")
        shape = np.asarray(grid.shape)
        for lo, hi in (corners - grid.origin) / grid.resolution:
            a = np.clip(np.floor(lo).astype(np.int64), 0, shape)
            b = np.clip(np.ceil(hi).astype(np.int64), 0, shape)
            grid.states[a[0] : b[0], a[1] : b[1], a[2] : b[2]] = OCCUPIED
        return grid

    def integrate_rays(
        self,
        origins: ArrayLike,
        endpoints: ArrayLike,
        hit: ArrayLike,
        carve_from: NDArray[np.float64] | None = None,
    ) -> None:
        """Clear the cells along each ray and mark the end cell of every hit occupied.

        Args:
            origins: one ``(3,)`` sensor position or ``(N, 3)`` ray origins (metres).
            endpoints: ``(N, 3)`` ray ends: the surface point for hits, the end of the sensor's
                range for rays that saw nothing.
            hit: ``(N,)`` whether each ray ended on a surface.
            carve_from: ``(N,)`` fraction of each ray before which it frees nothing
                (thinned carving, ``mapping.carving``); None frees every ray from its origin.
        """
        ends = as_points(endpoints, "ray end points", allow_empty=True)
        start = np.asarray(origins, dtype=np.float64)
        start = start.reshape(1, 3) if start.shape == (3,) else as_points(start, "ray origins")
        if start.shape[0] not in (1, len(ends)):
            raise InvalidInputError(f"{start.shape[0]} ray origins for {len(ends)} end points")
        if not np.all(np.isfinite(start)):
            raise InvalidInputError("ray origins must be finite")
        flags = np.asarray(hit, dtype=bool).reshape(-1)
        if flags.shape != (len(ends),):
            raise InvalidInputError(f"{flags.size} hit flags for {len(ends)} rays")
        starts = np.zeros(0) if carve_from is None else np.asarray(carve_from, dtype=np.float64)
        if starts.size and starts.shape != (len(ends),):
            raise InvalidInputError(f"{starts.size} carving starts for {len(ends)} rays")
        if not len(ends):
            return
        walk = partial(integrate_rays_kernel, self._cells, self.origin, self.resolution)
        if self.background:  # copies: the caller may reuse its arrays once this returns
            arrays = (start.copy(), ends.copy(), flags.copy(), starts.copy())
            self._pending.append(serial_worker("map").submit(walk, *arrays, sensor_threads()))
        else:
            self.settle()  # walks handed over before ``background`` was turned off go first
            walk(start, ends, flags, starts, sensor_threads())

    def integrate_frame(
        self,
        frame: Frame,
        stride: int = 4,
        use_odometry: bool = False,
        carving_spacing: float | None = None,
    ) -> None:
        """Integrate every ``stride``-th pixel of a depth frame (rows and columns).

        Pixels that saw nothing clear their ray up to the camera's range. With
        ``use_odometry`` the rays start from the pose the robot believed it had. With
        ``carving_spacing`` (cells) free space is carved by thinned rays near the camera
        (``mapping.carving``: approximate, faster); None walks every ray from the camera.
        """
        if not (isinstance(stride, int) and stride >= 1):
            raise InvalidInputError(f"stride must be a positive integer, got {stride!r}")
        rows, cols, flat, directions, cosine = _strided_pixels(frame.camera, stride)
        depth = frame.depth.ravel()[flat]
        hit = np.isfinite(depth)
        length = np.where(hit, depth, frame.camera.max_range) / cosine
        position, orientation = (
            (frame.odometry_position, frame.odometry_orientation)
            if use_odometry
            else (frame.position, frame.orientation)
        )
        rotation = Rotation.from_quat(orientation).as_matrix()
        ends = position + rotate_rows(directions * length[:, None], rotation)
        starts = None
        if carving_spacing is not None:
            # Neighbouring pixels of the strided grid are stride / fx radians apart at the centre,
            # the widest step of a pinhole camera.
            levels = np.minimum(
                carving.index_levels(rows // stride), carving.index_levels(cols // stride)
            )
            step = stride / frame.camera.fx
            starts = carving.carve_from(levels, length, step, self.resolution, carving_spacing)
        self.integrate_rays(position, ends, hit, starts)

    def integrate_scan(
        self,
        scan: LidarScan,
        clear_misses_to: float | None = None,
        carving_spacing: float | None = None,
    ) -> None:
        """Integrate a LiDAR scan: each return clears its ray and marks its end occupied.

        With ``clear_misses_to`` (metres, at most the sensor's range), beams that returned
        nothing also clear free space out to that distance, as OctoMap's max-range insertion
        does: open sky and far, empty streets become known free rather than staying unknown.
        With ``carving_spacing`` (cells) free space is carved by thinned beams near the sensor
        (``mapping.carving``, along each ring's columns: approximate, faster).
        """
        self.integrate_rays(
            scan.origin,
            scan.points,
            np.ones(len(scan.points), dtype=bool),
            self._thinned_starts(scan.points - scan.origin, carving_spacing),
        )
        if clear_misses_to is None or not len(scan.misses):
            return
        if not (math.isfinite(clear_misses_to) and 0 < clear_misses_to <= scan.max_range):
            raise InvalidInputError(
                f"clear_misses_to must be in (0, {scan.max_range}] m, got {clear_misses_to}"
            )
        reaches = scan.misses.astype(np.float64) * clear_misses_to
        self.integrate_rays(
            scan.origin,
            scan.origin + reaches,
            np.zeros(len(reaches), dtype=bool),
            self._thinned_starts(reaches, carving_spacing),
        )

    def _thinned_starts(
        self, rays: NDArray[np.float64], spacing: float | None
    ) -> NDArray[np.float64] | None:
        """Carving starts for beams (``rays``: end minus origin) listed along a LiDAR's rings,
        thinned by their order; None (exact) without a spacing."""
        if spacing is None:
            return None
        lengths = np.sqrt(np.einsum("ij,ij->i", rays, rays))
        step = carving.median_step(rays, lengths)
        if not (math.isfinite(step) and step > 0):
            return None  # too few beams to thin
        levels = carving.order_levels(len(rays))
        return carving.carve_from(levels, lengths, step, self.resolution, spacing)

    def inflated(self, radius: float) -> VoxelMap:
        """A copy where every cell within ``radius`` of an occupied cell is occupied.

        Distances are between cell centres; unknown cells stay unknown unless inflated.
        """
        if not (math.isfinite(radius) and radius >= 0):
            raise InvalidInputError(f"inflation radius must be >= 0, got {radius}")
        reach = math.floor(radius / self.resolution)
        states = self.states.copy()
        if reach:
            offsets = np.arange(-reach, reach + 1)
            ball = (
                np.add.outer(np.add.outer(offsets**2, offsets**2), offsets**2)
                <= (radius / self.resolution) ** 2
            )
            grown = ndimage.binary_dilation(states == OCCUPIED, structure=ball)
            states[grown] = OCCUPIED
        return VoxelMap(self.origin.copy(), self.resolution, states)

    def coarsened(self, resolution: float) -> VoxelMap:
        """The same box at a coarser ``resolution``: each coarse cell takes the highest state of
        the fine cells overlapping it (occupied over free over unknown, OctoMap's rule for inner
        nodes), so no obstacle is lost."""
        if not (math.isfinite(resolution) and resolution >= self.resolution):
            raise InvalidInputError(
                f"a coarser resolution than {self.resolution:g} m is needed, got {resolution!r}"
            )
        coarse = VoxelMap.empty(self.origin, self.upper, resolution)
        states = self.states
        for axis in range(3):
            states = _coarsen_axis(states, axis, self.resolution / resolution, coarse.shape[axis])
        coarse.states[:] = states
        return coarse


@lru_cache(maxsize=8)
def _strided_pixels(camera: CameraModel, stride: int) -> tuple[NDArray, ...]:
    """Every ``stride``-th pixel of ``camera``'s image (rows and columns): their rows, columns,
    flat indices, body-frame ray directions and those rays' x parts, computed once per camera
    (read-only: they are shared by every frame)."""
    rows, cols = np.meshgrid(
        np.arange(0, camera.height, stride), np.arange(0, camera.width, stride)
    )
    flat = (rows * camera.width + cols).ravel()
    directions, cosine = camera.rays
    pixels = (rows.ravel(), cols.ravel(), flat, directions[flat], cosine[flat])
    for array in pixels:
        array.flags.writeable = False
    return pixels


def _coarsen_axis(states: NDArray[np.uint8], axis: int, ratio: float, size: int) -> NDArray:
    """Max of the fine cells overlapping each coarse cell along one axis (``ratio`` < = 1)."""
    fine = np.arange(states.shape[axis])
    first = np.minimum(np.floor(fine * ratio + 1e-9).astype(np.int64), size - 1)
    last = np.minimum(np.floor((fine + 1) * ratio - 1e-9).astype(np.int64), size - 1)
    out_shape = list(states.shape)
    out_shape[axis] = size
    out = np.zeros(out_shape, dtype=np.uint8)
    for owner in (first, last):  # a fine cell overlaps at most two coarse ones
        starts = np.flatnonzero(np.diff(owner, prepend=-1))
        reduced = np.maximum.reduceat(states, starts, axis=axis)
        index: list[slice | NDArray[np.int64]] = [slice(None)] * 3
        index[axis] = owner[starts]
        out[tuple(index)] = np.maximum(out[tuple(index)], reduced)
    return out


def save_map(path: str | os.PathLike[str], voxel_map: VoxelMap, **extra: NDArray) -> Path:
    """Write a map as a compressed ``.npz`` (atomically), with ``extra`` arrays beside it that
    :func:`load_map` ignores (a program's own records, such as the site a prior was mapped in)."""
    return save_npz_atomic(
        path,
        format=np.array(MAP_FORMAT),
        version=np.array(MAP_VERSION),
        origin=voxel_map.origin,
        resolution=np.array(voxel_map.resolution),
        states=voxel_map.states,
        **extra,
    )


def load_map(path: str | os.PathLike[str]) -> VoxelMap:
    """Read a map written by :func:`save_map`; anything else is a :class:`FileFormatError`."""
    arrays = read_npz(Path(path))
    if "format" not in arrays or str(arrays["format"]) != MAP_FORMAT:
        raise FileFormatError(f"{path}: not a seminspect voxel map")
    if "version" not in arrays or int(arrays["version"]) != MAP_VERSION:
        raise FileFormatError(f"{path}: voxel map version {arrays.get('version')} is not supported")
    missing = [key for key in ("origin", "resolution", "states") if key not in arrays]
    if missing:
        raise FileFormatError(f"{path}: voxel map lacks {', '.join(missing)}")
    states = arrays["states"]
    if states.dtype != np.uint8 or states.ndim != 3 or states.size == 0 or states.max() > OCCUPIED:
        raise FileFormatError(f"{path}: voxel states must be a non-empty 3D array of 0, 1, 2")
    try:
        return VoxelMap(arrays["origin"], float(arrays["resolution"]), states)
    except (InvalidInputError, TypeError, ValueError) as exc:
        raise FileFormatError(f"{path}: {exc}") from None
