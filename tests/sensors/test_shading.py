"""The compiled shading pass against a plain numpy reference of the same formulas."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from seminspect.core.threads import rotate_rows
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.sensors import CameraModel
from seminspect.sensors.shading import (
    OCTAVE_WEIGHTS,
    OCTAVES,
    SKY_INTENSITY,
    shade_hits,
    surface_tables,
)
from sim_worlds import car_world

MASK = 0xFFFFFFFF


def _reference_hash(ix: np.ndarray, iy: np.ndarray, seed: np.ndarray) -> np.ndarray:
    h = ((ix * 0x27D4EB2D) ^ (iy * 0x165667B1) ^ (seed * 0x9E3779B1)) & MASK
    h ^= h >> 15
    h = (h * 0x2C1B3C6D) & MASK
    h ^= h >> 12
    h = (h * 0x297A2D39) & MASK
    h ^= h >> 15
    return (h & 0xFFFFFF) / 16777216.0


def _reference_shading(world, distance, face, *, directions, cosine, origin, pixel_angle):
    """Depth, labels and intensity, whole arrays at a time, in the kernel's operation order."""
    albedo, axes, seeds, light = surface_tables(world)
    hit = face >= 0
    f, t = face[hit], distance[hit]
    depth = np.full(len(face), np.inf, np.float32)
    depth[hit] = t * cosine[hit]
    labels = [np.zeros(len(face), table.dtype) for table in (world.face_instance, world.face_class)]
    for label, table in zip(labels, (world.face_instance, world.face_class), strict=True):
        label[hit] = table[f]
    rows = np.flatnonzero(hit)
    u = origin[axes[f, 0]] + t * directions[rows, axes[f, 0]]
    v = origin[axes[f, 1]] + t * directions[rows, axes[f, 1]]
    footprint = 2.0 * t * pixel_angle
    texture = np.zeros(len(rows))
    for k, (cell, weight) in enumerate(zip(OCTAVES, OCTAVE_WEIGHTS, strict=True)):
        cells = [np.floor(w / cell).astype(np.int64) for w in (u, v)]
        hashed = _reference_hash(*cells, seeds[f] + k)
        texture += np.where(cell < footprint, weight * 0.5, weight * hashed)
    value = 255.0 * albedo[f] * (0.35 + 0.65 * np.abs(light[f])) * (0.45 + 0.55 * texture)
    intensity = np.full(len(face), SKY_INTENSITY, np.uint8)
    intensity[hit] = np.minimum(255.0, value).astype(np.uint8)
    return depth, *labels, intensity


@pytest.mark.parametrize("yaw", [0.0, 0.7, 2.5])
def test_compiled_shading_equals_the_numpy_reference(yaw) -> None:
    world = car_world(yaw=0.3)
    camera = CameraModel(width=200, height=150)
    body, cosine = camera.rays
    origin = np.array([-6.0 * np.cos(yaw), -6.0 * np.sin(yaw), 1.2])
    rotation = Rotation.from_quat(quat_from_yaw(yaw)).as_matrix().astype(np.float32)
    directions = rotate_rows(body, rotation)
    distance, face = world.raycaster.cast(origin, directions, camera.ray_limits)
    assert 0.2 < np.mean(face >= 0) < 1.0  # sky and surfaces both in view
    count = len(face)
    outputs = [np.empty(count, dtype) for dtype in (np.float32, np.int32, np.int16, np.int16)]
    outputs.append(np.empty(count, np.uint8))
    shade_hits(
        distance,
        face,
        directions,
        cosine,
        origin,
        1.0 / camera.fx,
        world.face_instance,
        world.face_class,
        world.face_part,
        *surface_tables(world),
        OCTAVES,
        OCTAVE_WEIGHTS,
        *outputs,
    )
    expected = _reference_shading(
        world,
        distance,
        face,
        directions=directions,
        cosine=cosine,
        origin=origin,
        pixel_angle=1.0 / camera.fx,
    )
    intensity = expected[-1]
    for got, reference in zip(outputs[:3] + outputs[4:], expected, strict=True):
        np.testing.assert_array_equal(got, reference)
    assert len(np.unique(intensity[face >= 0])) > 20  # the texture varies over the car
