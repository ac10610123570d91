"""The camera and LiDAR of the 004 environment: their body-frame rays and the rays cast per step.

The body frame has x forward, y left and z up; the vehicle stays level, so a ray reaches the
world frame by the robot's heading alone (:func:`~seminspect.geometry.transforms.rotate_xy`).
:func:`sensor_rays` is compiled: it picks, room by room, the camera pixels worth casting; blocks
of rooms may be built on several threads.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import cast

import numba
import numpy as np
from numpy.typing import NDArray

from seminspect.core.threads import run_dealt
from seminspect.geometry.transforms import rotate_xy

#: rotate_xy compiled, typed for the scalars the kernels give it.
_rotate_xy = cast(
    Callable[[float, float, float, float], tuple[float, float]],
    numba.njit(inline="always")(rotate_xy),
)


def camera_rays(
    image_size: tuple[int, int], fov_deg: tuple[float, float]
) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """Body-frame unit rays of the pinhole camera, row by row, and their cosines to the axis."""
    width, height = image_size
    h_fov, v_fov = np.radians(fov_deg)
    u = (np.arange(width) + 0.5) / width * 2.0 - 1.0
    v = (np.arange(height) + 0.5) / height * 2.0 - 1.0
    uu, vv = np.meshgrid(u, v)
    rays = np.stack(
        [np.ones_like(uu), -uu * math.tan(h_fov / 2), -vv * math.tan(v_fov / 2)], axis=-1
    ).reshape(-1, 3)
    rays /= np.linalg.norm(rays, axis=1, keepdims=True)
    return rays.astype(np.float32), rays[:, 0].astype(np.float32)


def lidar_rays(beams: tuple[int, int]) -> NDArray[np.float32]:
    """Body-frame unit rays of a 360 x 90 deg LiDAR of (azimuth, elevation) ``beams``."""
    n_az, n_el = beams
    az = np.linspace(-math.pi, math.pi, n_az, endpoint=False)
    el = np.radians(np.linspace(-45.0, 45.0, n_el))
    aa, ee = np.meshgrid(az, el)
    rays = np.stack([np.cos(ee) * np.cos(aa), np.cos(ee) * np.sin(aa), np.sin(ee)], axis=-1)
    return rays.reshape(-1, 3).astype(np.float32)


def focus_mask(image_size: tuple[int, int]) -> NDArray[np.bool_]:
    """Central half of the image in each dimension: the focus area of 004 Sec III-C."""
    width, height = image_size
    cols = np.abs(np.arange(width) + 0.5 - width / 2) < width / 4
    rows = np.abs(np.arange(height) + 0.5 - height / 2) < height / 4
    return (rows[:, None] & cols[None, :]).reshape(-1)


def mapping_pixels(image_size: tuple[int, int]) -> NDArray[np.bool_]:
    """Every third pixel in each direction: the camera returns that feed the map.

    At the ego map's reach (about 1 m) their spacing is about 6 cm, finer than its 0.1 m cells.
    """
    width, height = image_size
    rows, cols = np.arange(height) % 3 == 1, np.arange(width) % 3 == 1
    return (rows[:, None] & cols[None, :]).reshape(-1)


def noisy_ranges(
    distance: NDArray[np.float64],
    noise: NDArray[np.float64],
    depth_noise: tuple[float, float],
    reach: float,
) -> NDArray[np.float64]:
    """Ranges with Gaussian noise whose sigma grows linearly with range (Sec III-E).

    ``noise`` holds a standard normal draw per range and ``depth_noise`` the ``(a, b)`` of
    sigma = a + b * range; ranges stay within ``[0, reach]``, misses (inf) stay misses.
    """
    a, b = depth_noise
    finite = np.isfinite(distance)
    clean = np.where(finite, distance, 0.0)
    noisy = np.clip(clean + noise * (a + b * clean), 0.0, reach)
    return np.where(finite, noisy, np.inf)


@numba.njit(cache=True)
def _slab(
    o: float, d: float, low: float, high: float, span: tuple[float, float]
) -> tuple[float, float]:
    """The part of the ray's parameter ``span`` within one axis' slab, with 1 mm of slack (the
    caster turns the rays in float32); empty when its low end passes its high end."""
    low, high = low - 1e-3, high + 1e-3
    if abs(d) < 1e-12:
        return span if low <= o <= high else (1.0, 0.0)
    t1, t2 = (low - o) / d, (high - o) / d
    return max(span[0], min(t1, t2)), min(span[1], max(t1, t2))


@numba.njit(cache=True)
def _hits_box(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    ox: float,
    oy: float,
    oz: float,
    dx: float,
    dy: float,
    dz: float,
    box: NDArray[np.float64],
    reach: float,
) -> bool:
    """Whether a ray may meet an axis-aligned box ``(low, high)`` within ``reach`` (slab test)."""
    span = _slab(ox, dx, box[0, 0], box[1, 0], (0.0, reach))
    span = _slab(oy, dy, box[0, 1], box[1, 1], span)
    span = _slab(oz, dz, box[0, 2], box[1, 2], span)
    return span[0] <= span[1]


#: Below this many rooms per thread, dealing a kernel's rooms out costs more than it saves.
MIN_ROOMS_PER_THREAD = 2

Rays = tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float32], NDArray[np.float32]]


def sensor_rays(  # noqa: PLR0917 - the kernel's arrays, positionally
    origin: NDArray[np.float64],
    yaw: NDArray[np.float64],
    camera: NDArray[np.float32],
    lidar: NDArray[np.float32],
    mapped: NDArray[np.bool_],
    target_box: NDArray[np.float64],
    reach: float,
    threads: int = 1,
) -> Rays:
    """The rays each room needs, grouped by room: (row, ray id, origin, direction).

    Camera pixels are cast when they may see the target (their ray meets its axis-aligned
    bound ``target_box``, ``(rooms, 2, 3)``: low and high corner, in the origins' frame) or
    when they belong to the mapping subset ``mapped``; every LiDAR beam is cast.
    A pixel left out can only see something other than the target, so the masked depth and
    the face reward are exact; only the map takes fewer (coarser) camera returns. Ray ids
    number the camera pixels first, then the LiDAR beams. With ``threads`` > 1 blocks of rooms
    are built on that many threads (:func:`~seminspect.core.threads.run_dealt`); the rays are
    the same, in the same order.
    """
    parts: dict[int, Rays] = {}

    def build(block: slice) -> None:
        if block.start == block.stop:  # more blocks than rooms: an empty one, keyed like the next
            return
        rows, ids, starts, dirs = _room_rays(
            origin[block], yaw[block], camera, lidar, mapped, target_box[block], reach
        )
        parts[block.start] = (rows + block.start, ids, starts, dirs)

    run_dealt(build, len(origin), threads, MIN_ROOMS_PER_THREAD)
    if len(parts) == 1:
        return parts[0]
    blocks = [parts[start] for start in sorted(parts)]
    row, ray, start, direction = (np.concatenate(column) for column in zip(*blocks, strict=True))
    return row, ray, start, direction


@numba.njit(cache=True, nogil=True)
def _room_rays(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    origin: NDArray[np.float64],
    yaw: NDArray[np.float64],
    camera: NDArray[np.float32],
    lidar: NDArray[np.float32],
    mapped: NDArray[np.bool_],
    target_box: NDArray[np.float64],
    reach: float,
) -> Rays:
    """:func:`sensor_rays` of a block of rooms, on one thread."""
    rows, ids = _rays_to_cast(origin, yaw, camera, lidar.shape[0], mapped, target_box, reach)
    starts, dirs = _world_rays(rows, ids, origin, yaw, camera, lidar)
    return rows, ids, starts, dirs


@numba.njit(cache=True, nogil=True)
def _rays_to_cast(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    origin: NDArray[np.float64],
    yaw: NDArray[np.float64],
    camera: NDArray[np.float32],
    n_lidar: int,
    mapped: NDArray[np.bool_],
    target_box: NDArray[np.float64],
    reach: float,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """(room row, ray id) of the mapping pixels, the pixels that may see the target, the beams."""
    n_cam = camera.shape[0]
    rows = np.empty(origin.shape[0] * (n_cam + n_lidar), dtype=np.int64)
    ids = np.empty_like(rows)
    count = 0
    for r in range(origin.shape[0]):
        c, s = math.cos(yaw[r]), math.sin(yaw[r])
        ox, oy, oz = origin[r, 0], origin[r, 1], origin[r, 2]
        for k in range(n_cam):
            keep = mapped[k]
            if not keep:
                dx, dy = _rotate_xy(c, s, camera[k, 0], camera[k, 1])
                keep = _hits_box(ox, oy, oz, dx, dy, camera[k, 2], target_box[r], reach)
            if keep:
                rows[count], ids[count] = r, k
                count += 1
        for k in range(n_lidar):
            rows[count], ids[count] = r, n_cam + k
            count += 1
    return rows[:count], ids[:count]


@numba.njit(cache=True, nogil=True)
def _world_rays(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    rows: NDArray[np.int64],
    ids: NDArray[np.int64],
    origin: NDArray[np.float64],
    yaw: NDArray[np.float64],
    camera: NDArray[np.float32],
    lidar: NDArray[np.float32],
) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """World-frame starts and directions of the rays ``(rows, ids)``."""
    n_cam = camera.shape[0]
    starts = np.empty((rows.shape[0], 3), dtype=np.float32)
    dirs = np.empty((rows.shape[0], 3), dtype=np.float32)
    for i in range(rows.shape[0]):
        r, k = rows[i], ids[i]
        body = camera[k] if k < n_cam else lidar[k - n_cam]
        c, s = math.cos(yaw[r]), math.sin(yaw[r])
        dirs[i, 0], dirs[i, 1] = _rotate_xy(c, s, body[0], body[1])
        dirs[i, 2] = body[2]
        starts[i, 0], starts[i, 1], starts[i, 2] = origin[r, 0], origin[r, 1], origin[r, 2]
    return starts, dirs
