"""A spinning multi-beam LiDAR, by default like the Velodyne VLP-16 of 000 Sec VI-A.

16 beams spread evenly over -15..+15 deg of elevation, a full turn of azimuth at a configurable
step (0.2 deg: 1800 columns, the VLP-16 at 10 Hz) and 100 m range. The sensor's frame is the
body frame it is given (x forward, z up); a scan returns the labelled hit points in the world
frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from seminspect.core.errors import InvalidInputError
from seminspect.core.threads import rotate_rows
from seminspect.geometry.transforms import Vec3, as_point, as_quaternion
from seminspect.sensors.noise import NoiseModel, require_rng
from seminspect.worlds import World


@dataclass(eq=False)
class LidarScan:
    """Labelled points of one scan, and the directions of the beams that returned nothing.

    Attributes:
        points: ``(N, 3)`` world coordinates of the returns.
        instance, class_id, part_id: labels per point, as in a camera frame.
        ring: beam index (0 = lowest) per point.
        origin: the sensor position.
        stamp: time of the scan (seconds).
        misses: ``(M, 3)`` world unit directions of the beams with no return within
            ``max_range``; mappers may clear free space along them (see
            :meth:`~seminspect.mapping.voxel.VoxelMap.integrate_scan`).
        max_range: the sensor's range (metres).
    """

    points: NDArray[np.float64]
    instance: NDArray[np.int32]
    class_id: NDArray[np.int16]
    part_id: NDArray[np.int16]
    ring: NDArray[np.int16]
    origin: Vec3
    stamp: float = 0.0
    misses: NDArray[np.float32] = field(default_factory=lambda: np.empty((0, 3), np.float32))
    max_range: float = math.inf


@dataclass(frozen=True)
class Lidar:
    """Beam layout and range of a spinning LiDAR."""

    beams: int = 16
    min_elevation_deg: float = -15.0
    max_elevation_deg: float = 15.0
    horizontal_resolution_deg: float = 0.2
    max_range: float = 100.0

    def __post_init__(self) -> None:
        if not (isinstance(self.beams, int) and 1 <= self.beams <= 256):
            raise InvalidInputError(f"LiDAR beams must be 1-256, got {self.beams!r}")
        low, high = self.min_elevation_deg, self.max_elevation_deg
        if not (-90.0 <= low <= high <= 90.0):
            raise InvalidInputError(f"LiDAR elevations must satisfy -90 <= {low} <= {high} <= 90")
        step = self.horizontal_resolution_deg
        if not (0.01 <= step <= 45.0):
            raise InvalidInputError(f"LiDAR horizontal resolution must be 0.01-45 deg, got {step}")
        if not (math.isfinite(self.max_range) and self.max_range > 0):
            raise InvalidInputError(f"LiDAR max range must be > 0, got {self.max_range}")

    @property
    def columns(self) -> int:
        return round(360.0 / self.horizontal_resolution_deg)

    @cached_property
    def rays(self) -> tuple[NDArray[np.float32], NDArray[np.int16]]:
        """Unit beam directions in the sensor frame ``(beams * columns, 3)`` and their rings."""
        elevation = np.radians(
            np.linspace(self.min_elevation_deg, self.max_elevation_deg, self.beams)
        )
        azimuth = np.arange(self.columns) * (2 * math.pi / self.columns)
        el, az = np.meshgrid(elevation, azimuth, indexing="ij")
        directions = np.stack(
            [np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=-1
        ).reshape(-1, 3)
        ring = np.repeat(np.arange(self.beams, dtype=np.int16), self.columns)
        return directions.astype(np.float32), ring

    def scan(
        self,
        world: World,
        position: ArrayLike,
        orientation: ArrayLike,
        *,
        noise: NoiseModel | None = None,
        rng: np.random.Generator | None = None,
        stamp: float = 0.0,
        threads: int = 1,
    ) -> LidarScan:
        """Cast every beam from the pose ``(position, orientation [x, y, z, w])``, on
        ``threads`` threads (the same scan on any number)."""
        origin = as_point(position, "LiDAR position")
        rotation = Rotation.from_quat(as_quaternion(orientation, "LiDAR orientation"))
        body, ring = self.rays
        directions = rotate_rows(body, rotation.as_matrix().astype(np.float32))
        distance, face = world.raycaster.cast(origin, directions, self.max_range, threads)
        returns = int(np.count_nonzero(face >= 0))
        range_noise = (
            require_rng(rng).normal(0.0, noise.lidar_range_noise_m, returns)
            if noise is not None and noise.lidar_range_noise_m
            else np.empty(0)
        )
        points, instance, class_id, part_id, rings, misses = _sort_returns(
            origin,
            directions,
            distance,
            face,
            range_noise,
            returns,
            world.face_instance,
            world.face_class,
            world.face_part,
            ring,
        )
        return LidarScan(
            points=points,
            instance=instance,
            class_id=class_id,
            part_id=part_id,
            ring=rings,
            origin=origin,
            stamp=float(stamp),
            misses=misses,
            max_range=self.max_range,
        )


@numba.njit(cache=True)
def _sort_returns(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    origin: np.ndarray,
    directions: np.ndarray,
    distance: np.ndarray,
    face: np.ndarray,
    range_noise: np.ndarray,
    returns: int,
    face_instance: np.ndarray,
    face_class: np.ndarray,
    face_part: np.ndarray,
    ring: np.ndarray,
):
    """The beams that hit a face (``returns`` of them), in beam order: their points (range plus
    ``range_noise`` where given, at least 0, along the beam from ``origin``), labels and rings;
    and the directions of the beams that returned nothing.

    One pass instead of a dozen boolean selections, with the numpy expressions' arithmetic:
    float64 ranges, ``origin + direction * range`` per coordinate
    (``tests/sensors/test_lidar.py`` holds them as the reference).
    """
    points = np.empty((returns, 3), np.float64)
    instance = np.empty(returns, face_instance.dtype)
    class_id = np.empty(returns, face_class.dtype)
    part_id = np.empty(returns, face_part.dtype)
    rings = np.empty(returns, ring.dtype)
    misses = np.empty((face.shape[0] - returns, 3), directions.dtype)
    noisy = range_noise.shape[0] > 0
    k = m = 0
    for beam in range(face.shape[0]):
        hit = face[beam]
        if hit < 0:
            misses[m] = directions[beam]
            m += 1
            continue
        reach = np.float64(distance[beam])
        if noisy:
            reach = max(reach + range_noise[k], 0.0)
        for axis in range(3):
            points[k, axis] = origin[axis] + np.float64(directions[beam, axis]) * reach
        instance[k], class_id[k], part_id[k] = face_instance[hit], face_class[hit], face_part[hit]
        rings[k] = ring[beam]
        k += 1
    return points, instance, class_id, part_id, rings, misses
