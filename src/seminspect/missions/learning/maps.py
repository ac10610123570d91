"""The robots' own maps in the 004 environment and the ego-centric maps the policy sees.

Each robot keeps a world-frame occupancy grid, built from its ranges only (004 Sec III-A), and
a grid of visit counts, both indexed (z, y, x). Every step the policy sees them resampled in
the yaw-aligned body frame: m^o, and m^h, the spatial visit score of eq (3). The loops over
rays and cells are compiled with numba.

The occupancy grid holds cell codes: :data:`UNSEEN` (never reached by a ray), :data:`OCCUPIED`
(a return fell in it) and :data:`FREE` (a ray passed through it). The binary map of policy v1
only ever marks returns, so there :data:`UNSEEN` reads free; the three-state map (004 Sec
III-A: "occupied, free or unknown") also carves free space along the rays
(:func:`carve_free`; :func:`update_maps` says which). :data:`BINARY_VALUES` and
:data:`THREE_STATE_VALUES` give what m^o shows.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

from seminspect.core.threads import run_dealt
from seminspect.missions.learning.sensors import MIN_ROOMS_PER_THREAD

#: Cell codes of the robots' world-frame occupancy grids.
UNSEEN, OCCUPIED, FREE = 0, 1, 2
#: What m^o shows per cell code, then for cells outside the grid: v1 reads outside as
#: occupied; the three-state map shows free 0, unknown 0.5 (outside too), occupied 1.
BINARY_VALUES = np.array([0.0, 1.0, 0.0, 1.0], dtype=np.float32)
THREE_STATE_VALUES = np.array([0.5, 1.0, 0.0, 0.5], dtype=np.float32)


@numba.njit(cache=True, nogil=True)
def mark_hits(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    occupancy: NDArray[np.uint8],
    env_of_ray: NDArray[np.int64],
    starts: NDArray[np.float32],
    dirs: NDArray[np.float32],
    distance: NDArray[np.float64],
    room_shift: NDArray[np.float64],
    row: NDArray[np.int64],
    resolution: float,
) -> None:
    """Mark the cell of every ranged return as occupied in its robot's own map (Sec III-A)."""
    nz, ny, nx = occupancy.shape[1], occupancy.shape[2], occupancy.shape[3]
    for i in range(distance.shape[0]):
        d = distance[i]
        if not math.isfinite(d):
            continue
        shift = room_shift[row[i]]
        x = starts[i, 0] - shift[0] + dirs[i, 0] * d
        y = starts[i, 1] - shift[1] + dirs[i, 1] * d
        z = starts[i, 2] - shift[2] + dirs[i, 2] * d
        a = min(max(math.floor(x / resolution), 0), nx - 1)
        b = min(max(math.floor(y / resolution), 0), ny - 1)
        m = min(max(math.floor(z / resolution), 0), nz - 1)
        occupancy[env_of_ray[i], m, b, a] = OCCUPIED


@numba.njit(inline="always")
def _walk_axis(origin: float, direction: float) -> tuple[int, int, float, float]:
    """One axis of a DDA walk in cell units: start cell, step, first crossing, crossing gap."""
    cell = math.floor(origin)
    if direction > 0.0:
        return cell, 1, (cell + 1 - origin) / direction, 1.0 / direction
    if direction < 0.0:
        return cell, -1, (cell - origin) / direction, -1.0 / direction
    return cell, 0, math.inf, math.inf


@numba.njit(cache=True, nogil=True)
def carve_free(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    occupancy: NDArray[np.uint8],
    env_of_ray: NDArray[np.int64],
    starts: NDArray[np.float32],
    dirs: NDArray[np.float32],
    distance: NDArray[np.float64],
    room_shift: NDArray[np.float64],
    row: NDArray[np.int64],
    resolution: float,
    reach: float,
) -> None:
    """Mark :data:`FREE` the cells each ray passes through up to its return (Sec III-A).

    A 3D DDA walk (Amanatides & Woo 1987) from the ray's start through every cell it enters
    before ``min(range, reach)`` (misses: ``reach``), stopping where it leaves the grid. Run
    it before :func:`mark_hits`, so that within one step a return's cell ends occupied: a hit
    wins over a pass.
    """
    nz, ny, nx = occupancy.shape[1], occupancy.shape[2], occupancy.shape[3]
    for n in range(distance.shape[0]):
        d = distance[n]
        end = (min(d, reach) if math.isfinite(d) else reach) / resolution  # unit dirs: cells
        shift, env = room_shift[row[n]], env_of_ray[n]
        i, si, ti, di = _walk_axis((starts[n, 0] - shift[0]) / resolution, dirs[n, 0])
        j, sj, tj, dj = _walk_axis((starts[n, 1] - shift[1]) / resolution, dirs[n, 1])
        k, sk, tk, dk = _walk_axis((starts[n, 2] - shift[2]) / resolution, dirs[n, 2])
        t = 0.0
        while t < end and 0 <= i < nx and 0 <= j < ny and 0 <= k < nz:
            occupancy[env, k, j, i] = FREE
            if ti <= tj and ti <= tk:
                t, ti, i = ti, ti + di, i + si
            elif tj <= tk:
                t, tj, j = tj, tj + dj, j + sj
            else:
                t, tk, k = tk, tk + dk, k + sk


def update_maps(  # noqa: PLR0917 - the kernels' arrays, positionally
    occupancy: NDArray[np.uint8],
    env_of_ray: NDArray[np.int64],
    starts: NDArray[np.float32],
    dirs: NDArray[np.float32],
    distance: NDArray[np.float64],
    room_shift: NDArray[np.float64],
    row: NDArray[np.int64],
    resolution: float,
    carve: NDArray[np.bool_] | None,
    reach: float,
    threads: int = 1,
) -> None:
    """One step's rays into the robots' maps: those flagged in ``carve`` carve free space up
    to ``reach`` (:func:`carve_free`; None: none carve, the binary map), then every return
    marks its cell (:func:`mark_hits`).

    The rays come grouped by room (``row`` ascending, one row per ``room_shift``), so blocks of
    rooms are dealt out to ``threads`` (:func:`~seminspect.core.threads.run_dealt`); each room
    writes only its own robot's map, so the maps do not depend on the split.
    """
    rooms = np.arange(len(room_shift) + 1)
    hits = np.searchsorted(row, rooms)
    free = np.flatnonzero(carve) if carve is not None else np.zeros(0, dtype=np.int64)
    walk_env, walk_row, walk_length = env_of_ray[free], row[free], distance[free]
    walk_start, walk_dir = starts[free], dirs[free]
    walked = np.searchsorted(walk_row, rooms)

    def update(block: slice) -> None:
        if carve is not None:
            w = slice(walked[block.start], walked[block.stop])
            carve_free(
                occupancy, walk_env[w], walk_start[w], walk_dir[w], walk_length[w], room_shift,
                walk_row[w], resolution, reach,
            )  # fmt: skip
        part = slice(hits[block.start], hits[block.stop])
        mark_hits(
            occupancy, env_of_ray[part], starts[part], dirs[part], distance[part], room_shift,
            row[part], resolution,
        )  # fmt: skip

    run_dealt(update, len(room_shift), threads, MIN_ROOMS_PER_THREAD)


def ego_offsets(cells: int, resolution: float) -> NDArray[np.float64]:
    """Body-frame centres of the n^3 ego-map cells, x fastest-varying last (D, H, W = z, y, x)."""
    half = cells // 2
    steps = (np.arange(cells) - half) * resolution
    zz, yy, xx = np.meshgrid(steps, steps, steps, indexing="ij")
    return np.stack([xx, yy, zz], axis=-1).reshape(-1, 3)


@numba.njit(cache=True, nogil=True)
def gather_ego(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    occupancy: NDArray[np.uint8],
    visits: NDArray[np.uint16],
    rows: NDArray[np.int64],
    position: NDArray[np.float64],
    yaw: NDArray[np.float64],
    offsets: NDArray[np.float64],
    resolution: float,
    values: NDArray[np.float32],
    out_occupancy: NDArray[np.float32],
    out_visits: NDArray[np.float32],
) -> None:
    """Sample the robots' world-frame maps at the yaw-rotated ego cells.

    ``values`` maps each cell code to what m^o shows, its last entry the value outside the grid
    (:data:`BINARY_VALUES`, :data:`THREE_STATE_VALUES`).
    """
    outside = values[values.shape[0] - 1]
    nz, ny, nx = occupancy.shape[1], occupancy.shape[2], occupancy.shape[3]
    for r in range(rows.shape[0]):
        env = rows[r]
        c, s = math.cos(yaw[r]), math.sin(yaw[r])
        px, py, pz = position[r, 0], position[r, 1], position[r, 2]
        for k in range(offsets.shape[0]):
            ox, oy, oz = offsets[k, 0], offsets[k, 1], offsets[k, 2]
            # Not rotate_xy: the position is added first, (px + c ox) - s oy, which rounds
            # otherwise, and the shipped policy was trained on these cells.
            i = math.floor((px + c * ox - s * oy) / resolution)
            j = math.floor((py + s * ox + c * oy) / resolution)
            m = math.floor((pz + oz) / resolution)
            if 0 <= i < nx and 0 <= j < ny and 0 <= m < nz:
                out_occupancy[r, k] = values[occupancy[env, m, j, i]]
                out_visits[r, k] = visits[env, m, j, i]
            else:
                out_occupancy[r, k] = outside
                out_visits[r, k] = 0.0


def ego_maps(  # noqa: PLR0917 - the kernel's arrays, positionally
    occupancy: NDArray[np.uint8],
    visits: NDArray[np.uint16],
    rows: NDArray[np.int64],
    position: NDArray[np.float64],
    yaw: NDArray[np.float64],
    offsets: NDArray[np.float64],
    resolution: float,
    values: NDArray[np.float32],
    threads: int = 1,
) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """:func:`gather_ego` into new ``(rows, cells)`` arrays of m^o values and visit counts,
    blocks of rows dealt out to ``threads`` (each row on its own: the same numbers)."""
    out_occupancy = np.empty((len(rows), len(offsets)), dtype=np.float32)
    out_visits = np.empty_like(out_occupancy)

    def gather(block: slice) -> None:
        gather_ego(
            occupancy, visits, rows[block], position[block], yaw[block], offsets, resolution,
            values, out_occupancy[block], out_visits[block],
        )  # fmt: skip

    run_dealt(gather, len(rows), threads, MIN_ROOMS_PER_THREAD)
    return out_occupancy, out_visits


@numba.njit(cache=True)
def _entropy_in_place(counts: NDArray[np.float32], totals: NDArray[np.float64]) -> None:
    """Rows of visit counts -> -p log p with p = count / row total (eq (3)); totals out."""
    for r in range(counts.shape[0]):
        total = 0.0
        for k in range(counts.shape[1]):
            total += counts[r, k]
        totals[r] = total
        if total <= 0.0:
            continue
        for k in range(counts.shape[1]):
            if counts[r, k] > 0.0:
                p = counts[r, k] / total
                counts[r, k] = -p * math.log(p)


def spatial_visit_scores(counts: NDArray) -> tuple[NDArray[np.float32], NDArray[np.float64]]:
    """004 eq (3): m^h = -p log p, p the visits of a cell over the local total N_t.

    ``counts`` is ``(rows, cells)``; returns the scores and N_t of each row.
    """
    scores = np.array(counts, dtype=np.float32, copy=True)
    totals = np.empty(len(scores))
    _entropy_in_place(scores, totals)
    return scores, totals
