"""The robots' own maps in the 004 environment and the ego-centric maps the policy sees.

Each robot keeps a world-frame occupancy grid, built from its ranges only (004 Sec III-A), and
a grid of visit counts, both indexed (z, y, x). Every step the policy sees them resampled in
the yaw-aligned body frame: m^o, and m^h, the spatial visit score of eq (3). The loops over
rays and cells are compiled with numba.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray


@numba.njit(cache=True)
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
        occupancy[env_of_ray[i], m, b, a] = 1


def ego_offsets(cells: int, resolution: float) -> NDArray[np.float64]:
    """Body-frame centres of the n^3 ego-map cells, x fastest-varying last (D, H, W = z, y, x)."""
    half = cells // 2
    steps = (np.arange(cells) - half) * resolution
    zz, yy, xx = np.meshgrid(steps, steps, steps, indexing="ij")
    return np.stack([xx, yy, zz], axis=-1).reshape(-1, 3)


@numba.njit(cache=True)
def gather_ego(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    occupancy: NDArray[np.uint8],
    visits: NDArray[np.uint16],
    rows: NDArray[np.int64],
    position: NDArray[np.float64],
    yaw: NDArray[np.float64],
    offsets: NDArray[np.float64],
    resolution: float,
    out_occupancy: NDArray[np.float32],
    out_visits: NDArray[np.float32],
) -> None:
    """Sample the robots' world-frame maps at the yaw-rotated ego cells (outside: occupied)."""
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
                out_occupancy[r, k] = occupancy[env, m, j, i]
                out_visits[r, k] = visits[env, m, j, i]
            else:
                out_occupancy[r, k] = 1.0
                out_visits[r, k] = 0.0


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
