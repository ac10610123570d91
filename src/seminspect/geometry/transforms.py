"""Rotations and metric-vector validation.

Orientations are unit quaternions in scalar-last ``[x, y, z, w]`` order, the convention of
:class:`scipy.spatial.transform.Rotation` and ROS. (One exception lies outside this module:
the state observation of the learned policy, ``missions.learning.env``, carries its
quaternion scalar-first, ``(w, x, y, z)``, the order that policy was trained on.)

Vehicles stay level unless a pitch is named: a heading (yaw) turns about +Z, with the body
frame's x forward and y to the left.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from seminspect.core.errors import InvalidInputError

Vec3 = NDArray[np.float64]
Quat = NDArray[np.float64]

IDENTITY_QUAT: Quat = np.array([0.0, 0.0, 0.0, 1.0])

#: Coordinates :func:`rotate_xy` turns: floats, or arrays of them.
_Planar = TypeVar("_Planar", float, NDArray[np.float64])


def as_point(value: ArrayLike, what: str = "position") -> Vec3:
    """A finite 3-vector as a fresh float64 array, or :class:`InvalidInputError`."""
    try:
        point = np.array(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{what} must be three numbers, got {value!r}") from None
    if point.shape != (3,):
        raise InvalidInputError(f"{what} must have 3 coordinates, got {point.size}")
    if not all(map(math.isfinite, point.tolist())):  # ten times faster than numpy for three
        raise InvalidInputError(f"{what} must be finite, got {point.tolist()}")
    return point


def as_points(value: ArrayLike, what: str = "points", allow_empty: bool = False) -> NDArray:
    """A finite ``(N, 3)`` float64 array, or :class:`InvalidInputError`."""
    try:
        points = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{what} must be an (N, 3) array of numbers") from None
    if points.ndim != 2 or points.shape[1] != 3:
        raise InvalidInputError(f"{what} must have shape (N, 3), got {points.shape}")
    if points.shape[0] == 0 and not allow_empty:
        raise InvalidInputError(f"{what} is empty")
    if not np.all(np.isfinite(points)):
        raise InvalidInputError(f"{what} contains NaN or infinite coordinates")
    return points


def as_quaternion(value: ArrayLike, what: str = "orientation") -> Quat:
    """A unit quaternion ``[x, y, z, w]`` (normalised), or :class:`InvalidInputError`."""
    try:
        quat = np.array(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{what} must be a quaternion [x, y, z, w]") from None
    if quat.shape != (4,) or not np.all(np.isfinite(quat)):
        raise InvalidInputError(f"{what} must be 4 finite numbers [x, y, z, w], got {value!r}")
    norm = float(np.linalg.norm(quat))
    if norm < 1e-9:
        raise InvalidInputError(f"{what} is a zero quaternion")
    return quat / norm


def quat_from_yaw(yaw: float) -> Quat:
    """Quaternion of a rotation by ``yaw`` radians about +Z."""
    if not math.isfinite(yaw):
        raise InvalidInputError(f"yaw must be finite, got {yaw}")
    half = 0.5 * yaw
    return np.array([0.0, 0.0, math.sin(half), math.cos(half)])


def yaw_from_quat(quat: Sequence[float] | Quat) -> float:
    """Heading (rotation about +Z) of a quaternion ``[x, y, z, w]``, in ``(-pi, pi]``."""
    x, y, z, w = (float(c) for c in quat)
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def quat_from_yaw_pitch(yaw: float, pitch: float) -> Quat:
    """Quaternion of a heading ``yaw`` about +Z, then ``pitch`` about the turned +Y (nose
    down for a positive pitch): how a camera on a level vehicle looks."""
    return Rotation.from_euler("ZY", [yaw, pitch]).as_quat()


def yaw_rotation(yaw: float) -> Rotation:
    """The rotation by ``yaw`` radians about +Z."""
    return Rotation.from_euler("z", yaw)


def reframe_points(
    points: NDArray[np.float64],
    origin_from: Vec3,
    yaw_from: float,
    origin_to: Vec3,
    yaw_to: float,
) -> NDArray[np.float64]:
    """Points moved between two frames in which one level pose reads differently.

    The pose is ``(origin_from, yaw_from)`` in the frame of ``points`` and ``(origin_to,
    yaw_to)`` in the frame returned, e.g. a robot's odometry pose and its true pose.
    """
    return yaw_rotation(yaw_to - yaw_from).apply(points - origin_from) + origin_to


def rotate_xy(
    cos_yaw: _Planar, sin_yaw: _Planar, x: _Planar, y: _Planar
) -> tuple[_Planar, _Planar]:
    """``(x, y)`` turned counter-clockwise about +Z by the angle of cosine ``cos_yaw`` and sine
    ``sin_yaw``: the one planar rotation, on floats or arrays alike.

    Plain arithmetic, so numba compiles it too (the learning environment's ray kernels): those
    take the cosine and sine once per robot and turn thousands of rays with them. numba's cache
    checks only the calling kernel's file, so after editing this function clear the cached
    kernels (``find src -name '*.nbi' -delete``) before trusting a run.
    """
    return cos_yaw * x - sin_yaw * y, sin_yaw * x + cos_yaw * y


def world_from_body(vectors: NDArray, yaw: NDArray) -> NDArray[np.float64]:
    """Rows of body-frame vectors in the world frame of level vehicles with headings ``yaw``."""
    x, y = rotate_xy(np.cos(yaw), np.sin(yaw), vectors[:, 0], vectors[:, 1])
    return np.stack([x, y, vectors[:, 2]], 1)


def body_from_world(vectors: NDArray, yaw: NDArray) -> NDArray[np.float64]:
    """Rows of world-frame vectors in the body frame of level vehicles with headings ``yaw``."""
    x, y = rotate_xy(np.cos(yaw), -np.sin(yaw), vectors[:, 0], vectors[:, 1])
    return np.stack([x, y, vectors[:, 2]], 1)


def matrix_from_euler_xyz(angles: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rotation matrix of turns by ``angles`` about the fixed x, y then z axes (Rz Ry Rx).

    Written out rather than taken from :class:`~scipy.spatial.transform.Rotation`, whose
    ``from_euler("xyz", ...)`` agrees to rounding only: the learning rooms are built from
    these exact matrices.
    """
    (ca, cb, cc), (sa, sb, sc) = np.cos(angles), np.sin(angles)
    rx = np.array([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
    ry = np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    rz = np.array([[cc, -sc, 0], [sc, cc, 0], [0, 0, 1]])
    return rz @ ry @ rx


def wrap_angle(angle: float) -> float:
    """Wrap an angle to ``(-pi, pi]``."""
    wrapped = math.remainder(angle, math.tau)
    return math.pi if wrapped == -math.pi else wrapped


def bearing_offset(origin: ArrayLike, heading: float, point: ArrayLike) -> float:
    """Absolute horizontal angle between ``heading`` and the direction ``origin -> point``."""
    delta = np.asarray(point, dtype=np.float64)[:2] - np.asarray(origin, dtype=np.float64)[:2]
    if not np.any(delta):
        return 0.0
    return abs(wrap_angle(math.atan2(delta[1], delta[0]) - heading))
