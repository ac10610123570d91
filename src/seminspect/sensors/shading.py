"""Per-pixel shading of ray hits: depth, labels and a stable textured intensity.

The intensity of a pixel is a function of the surface point it sees, never of the viewpoint, so a
feature matcher (ORB, SIFT) finds the same keypoints when a surface is seen again (the
scene-similarity check of 000 eq (8)):

* texture: three octaves of blocky value noise (0.45, 0.15 and 0.05 m cells) over the two world
  axes most parallel to the face, seeded per face plane so that parallel surfaces differ; an
  octave whose cells are smaller than two pixels at the hit's range is replaced by its mean,
  which keeps distant surfaces from aliasing into flicker;
* albedo: a fixed grey level per (class, part), so part borders show as edges;
* shading: Lambert with a fixed sun, two-sided, plus ambient light.
"""

from __future__ import annotations

import weakref

import numba
import numpy as np
from numpy.typing import NDArray

from seminspect.worlds import World

#: Direction towards the sun (normalised below); fixed so shading never depends on the view.
SUN = np.array([0.35, 0.25, 0.9]) / np.linalg.norm([0.35, 0.25, 0.9])
SKY_INTENSITY = 170
OCTAVES = np.array([0.45, 0.15, 0.05])
OCTAVE_WEIGHTS = np.array([0.5, 0.3, 0.2])

_TABLES: weakref.WeakKeyDictionary[World, tuple] = weakref.WeakKeyDictionary()


@numba.njit(cache=True, inline="always")
def _hash(ix: int, iy: int, seed: int) -> float:
    """A well-mixed value in [0, 1) for integer lattice coordinates and a seed."""
    h = (ix * 0x27D4EB2D) ^ (iy * 0x165667B1) ^ (seed * 0x9E3779B1)
    h &= 0xFFFFFFFF
    h ^= h >> 15
    h = (h * 0x2C1B3C6D) & 0xFFFFFFFF
    h ^= h >> 12
    h = (h * 0x297A2D39) & 0xFFFFFFFF
    h ^= h >> 15
    return (h & 0xFFFFFF) / 16777216.0


@numba.njit(cache=True, nogil=True)
def shade_hits(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    distance: np.ndarray,
    face: np.ndarray,
    directions: np.ndarray,
    axis_cosine: np.ndarray,
    origin: np.ndarray,
    pixel_angle: float,
    face_instance: np.ndarray,
    face_class: np.ndarray,
    face_part: np.ndarray,
    albedo: np.ndarray,
    plane_axes: np.ndarray,
    plane_seed: np.ndarray,
    light: np.ndarray,
    octaves: np.ndarray,
    weights: np.ndarray,
    depth: np.ndarray,
    instance: np.ndarray,
    class_id: np.ndarray,
    part_id: np.ndarray,
    intensity: np.ndarray,
) -> None:
    """Fill the per-pixel outputs (flat arrays) from ray distances and face indices; an empty
    ``intensity`` leaves the intensity out (the texture is most of the work).

    Neighbouring pixels mostly see the same texture cell, so each octave keeps its last cell
    and value and hashes only when the cell changes (the same values, fewer hashes).
    """
    grey = intensity.shape[0] > 0
    last_cell = np.zeros((octaves.shape[0], 3), dtype=np.int64)  # ix, iy and seed per octave
    last_cell[:, 2] = -1  # seeds are >= 0: no match
    last_value = np.zeros(octaves.shape[0])
    for i in range(distance.shape[0]):
        f = face[i]
        if f < 0:
            depth[i] = np.inf
            instance[i] = 0
            class_id[i] = 0
            part_id[i] = 0
            if grey:
                intensity[i] = SKY_INTENSITY
            continue
        t = distance[i]
        depth[i] = t * axis_cosine[i]
        instance[i] = face_instance[f]
        class_id[i] = face_class[f]
        part_id[i] = face_part[f]
        if not grey:
            continue
        a = plane_axes[f, 0]
        b = plane_axes[f, 1]
        u = origin[a] + t * directions[i, a]
        v = origin[b] + t * directions[i, b]
        texture = texture_value(
            u, v, 2.0 * t * pixel_angle, plane_seed[f], octaves, weights, last_cell, last_value
        )
        intensity[i] = _grey_level(albedo[f], light[f], texture)


@numba.njit(cache=True, inline="always")
def texture_value(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    u: float,
    v: float,
    footprint: float,
    plane_seed: int,
    octaves: np.ndarray,
    weights: np.ndarray,
    last_cell: np.ndarray,
    last_value: np.ndarray,
) -> float:
    """The value noise at ``(u, v)`` on a face plane, in [0, 1): octaves whose cells are
    smaller than the pixel ``footprint`` count at their mean. ``last_cell`` and ``last_value``
    hold each octave's last cell and its value, updated here."""
    texture = 0.0
    for k in range(octaves.shape[0]):
        cell = octaves[k]
        if cell < footprint:
            texture += weights[k] * 0.5
        else:
            ix = int(np.floor(u / cell))
            iy = int(np.floor(v / cell))
            seed = plane_seed + k
            if ix != last_cell[k, 0] or iy != last_cell[k, 1] or seed != last_cell[k, 2]:
                last_cell[k, 0], last_cell[k, 1], last_cell[k, 2] = ix, iy, seed
                last_value[k] = _hash(ix, iy, seed)
            texture += weights[k] * last_value[k]
    return texture


@numba.njit(cache=True, inline="always")
def _grey_level(albedo: float, sun_cosine: float, texture: float) -> np.uint8:
    """Lambert shading, two-sided, with ambient light, over the albedo and texture."""
    value = 255.0 * albedo * (0.35 + 0.65 * abs(sun_cosine)) * (0.45 + 0.55 * texture)
    return np.uint8(min(255.0, value))


def surface_tables(world: World) -> tuple[NDArray, ...]:
    """Per-face albedo, texture axes, texture seed and sun cosine (cached per world)."""
    cached = _TABLES.get(world)
    if cached is not None:
        return cached
    normals = world.face_normals
    dominant = np.argmax(np.abs(normals), axis=1)
    axes = np.array([[1, 2], [0, 2], [0, 1]], dtype=np.int64)[dominant]
    # Seed each face by its plane (normal axis and offset to 5 cm), so coplanar faces share one
    # texture and parallel faces (a car's left and right doors) do not.
    offset = np.einsum("ij,ij->i", normals, world.triangles[:, 0])
    plane = (
        np.round(offset / 0.05).astype(np.int64) * 7
        + dominant * 2
        + (normals[np.arange(len(normals)), dominant] > 0)
    )
    seed = (plane * 2654435761 % 2147483647).astype(np.int64)
    label = world.face_class.astype(np.int64) * 131 + world.face_part.astype(np.int64) * 17
    albedo = 0.35 + 0.5 * ((label * 2654435761) % 1000 / 1000.0)
    tables = (
        albedo.astype(np.float64),
        np.ascontiguousarray(axes),
        seed,
        (normals @ SUN).astype(np.float64),
    )
    _TABLES[world] = tables
    return tables
