"""Surface normals from a depth image and the viewpoint utility of 002 Sec IV.

Each pixel is back-projected to a 3D point in the camera's optical frame; the normal is the
cross product of the image-space gradients of those points (the depth-gradient estimate of
Nakagawa et al., 002 ref [15]). The viewpoint utility is the mean, over valid pixels, of the
cosine of the incidence angle between the viewing ray and the surface normal: 1 when every
pixel sees its surface head-on, towards 0 at grazing angles.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError


def depth_points(depth: ArrayLike, focal: float) -> NDArray[np.float64]:
    """``(H, W, 3)`` optical-frame points (x right, y down, z forward; NaN without depth) of a
    z-depth image with square pixels of focal length ``focal`` [px], principal point centred."""
    z = np.array(depth, dtype=np.float64)
    if z.ndim != 2 or min(z.shape) < 3:
        raise InvalidInputError(f"depth image must be 2D and at least 3x3, got {z.shape}")
    if not (math.isfinite(focal) and focal > 0):
        raise InvalidInputError(f"focal length must be > 0 pixels, got {focal}")
    z[~np.isfinite(z)] = np.nan  # no return: no point
    height, width = z.shape
    v, u = np.mgrid[0:height, 0:width].astype(np.float64)
    x = (u - (width - 1) / 2) * z / focal
    y = (v - (height - 1) / 2) * z / focal
    return np.stack([x, y, z], axis=-1)


def depth_normals(depth: ArrayLike, focal: float) -> NDArray[np.float64]:
    """``(H, W, 3)`` unit normals facing the camera; NaN where a neighbour has no depth."""
    points = depth_points(depth, focal)
    along_v, along_u = np.gradient(points, axis=(0, 1))
    normals = np.cross(along_u, along_v)
    length = np.linalg.norm(normals, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        normals = normals / length
    facing = np.sign(-(normals * points).sum(axis=-1, keepdims=True))
    return normals * np.where(facing == 0, 1.0, facing)


def incidence_cosines(depth: ArrayLike, focal: float) -> NDArray[np.float64]:
    """Cosine of the incidence angle per pixel with a valid normal (a flat array)."""
    points = depth_points(depth, focal)
    normals = depth_normals(depth, focal)
    rays = points / np.linalg.norm(points, axis=-1, keepdims=True)
    cosines = np.abs((normals * rays).sum(axis=-1))
    return cosines[np.isfinite(cosines)]


def viewpoint_utility(depth: ArrayLike, focal: float) -> float:
    """002 Sec IV: mean incidence cosine over valid pixels (NaN when no pixel is valid)."""
    cosines = incidence_cosines(depth, focal)
    return float(cosines.mean()) if len(cosines) else math.nan
