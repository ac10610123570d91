"""Which faces of a room's target can be inspected at all under the strict coverage rule.

004 scores coverage against the "feasible" surface: obstacles and the target itself leave
some faces impossible to inspect (Sec IV-A, Fig 5: "the ideal feasible coverage accounts for
occlusions"). Here a face is feasible when some viewpoint on the ``d_ref +- strict_band``
shell around it, within ``strict_incidence_deg`` of its normal, is

* free for the robot: clearance to the walls and every solid of at least ``robot_radius``
  (which also keeps it inside the room);
* in line of sight: the ray from it to the face point first hits that face;
* in the vertical focus band of the level camera: the focus area is the central half of the
  image (004 Sec III-C), and the yaw is free, so only the elevation is bounded;
* close enough that the face covers ``strict_min_pixels`` pixels of the image.

A face stands for itself by its area-weighted centre and normal (the strict rule averages
range and incidence over its pixels). It is decided by sampled viewpoints (a fixed number per
face, drawn from a seed), not by what a controller saw, so every controller is scored against
the same faces.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from seminspect.core.rng import make_rng
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.rooms import TARGET_FACES, Room, clearance
from seminspect.worlds.raycast import RayCaster

#: Viewpoints sampled per face; 256 keep a face whose free viewpoints fill 2 % of its shell
#: from being missed more than once in 170 rooms ((1 - 0.02)^256 < 0.006).
SAMPLES_PER_FACE = 256
#: The ray to a face point may end this far beyond it (float32 casting, curved faces).
_SIGHT_SLACK = 1e-2


def face_geometry(
    room: Room,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Area-weighted centre, unit area-weighted (outward) normal and area of each target face.

    Each is ``(TARGET_FACES, ...)``, from the room's triangles and ``face_of_triangle``.
    """
    on_target = room.face_of_triangle >= 0
    face = room.face_of_triangle[on_target]
    corners = room.vertices[room.triangles[on_target]]
    # |cross| is twice the triangle's area, so summing it weights each normal by area.
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    double_area = np.linalg.norm(cross, axis=1)
    area = np.asarray(0.5 * np.bincount(face, double_area, TARGET_FACES), dtype=np.float64)
    centre = (
        np.stack(
            [np.bincount(face, double_area * c, TARGET_FACES) for c in corners.mean(axis=1).T],
            axis=1,
        )
        / np.maximum(2.0 * area, 1e-300)[:, None]
    )
    normal = np.stack(
        [np.bincount(face, c, TARGET_FACES) for c in cross.T], axis=1, dtype=np.float64
    )
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-300)
    return centre, normal, area


def _cone_samples(
    normal: NDArray[np.float64], config: EnvConfig, rng: np.random.Generator
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(F, S, 3)`` unit directions from each face towards its viewpoints, uniform on the cap
    within the incidence limit of its normal, and their ``(F, S)`` distances on the shell."""
    faces = len(normal)
    cos_limit = math.cos(math.radians(config.strict_incidence_deg))
    cos_t = rng.uniform(cos_limit, 1.0, (faces, SAMPLES_PER_FACE))  # uniform on the cap
    phi = rng.uniform(0.0, 2.0 * math.pi, (faces, SAMPLES_PER_FACE))
    # nearer than robot_radius the viewpoint would touch the face: never free
    low = max(config.d_ref - config.strict_band, config.robot_radius)
    distance = rng.uniform(low, config.d_ref + config.strict_band, (faces, SAMPLES_PER_FACE))
    # An orthonormal frame (t1, t2, normal) per face; the helper axis is never along the normal.
    helper = np.where(np.abs(normal[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    t1 = np.cross(helper, normal)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(normal, t1)
    sin_t = np.sqrt(1.0 - cos_t**2)
    direction = (
        (sin_t * np.cos(phi))[..., None] * t1[:, None]
        + (sin_t * np.sin(phi))[..., None] * t2[:, None]
        + cos_t[..., None] * normal[:, None]
    )
    return direction, distance


def _pixel_solid_angle(config: EnvConfig) -> float:
    """Solid angle (sr) of the image's centre pixel: the largest, so pixel counts are low."""
    width, height = config.image_size
    h_fov, v_fov = np.radians(config.fov_deg)
    return float(2.0 * math.tan(h_fov / 2) / width * 2.0 * math.tan(v_fov / 2) / height)


def feasible_faces(room: Room, config: EnvConfig, seed: int = 0) -> NDArray[np.bool_]:
    """``(TARGET_FACES,)``: whether some sampled viewpoint could inspect each face strictly.

    Args:
        room: the room (its triangles, solids and target faces).
        config: ``d_ref``, the strict rule, the camera and ``robot_radius``.
        seed: the viewpoints' draw; the same room and seed give the same answer.
    """
    centre, normal, area = face_geometry(room)
    direction, distance = _cone_samples(normal, config, make_rng(seed, "learning", "feasible"))
    viewpoint = (centre[:, None] + direction * distance[..., None]).reshape(-1, 3)
    towards = -direction.reshape(-1, 3)  # from the viewpoint to the face point
    reach = distance.reshape(-1)
    # Level camera, yaw free: put the face point in the centre column; the focus rows then
    # span |tan(elevation)| < tan(v_fov / 2) / 2 (the pinhole rays of sensors.camera_rays).
    band = math.tan(math.radians(config.fov_deg[1]) / 2) / 2
    level = np.abs(towards[:, 2]) < band * np.hypot(towards[:, 0], towards[:, 1])
    cos_incidence = (direction * normal[:, None]).sum(axis=-1).reshape(-1)
    face_index = np.repeat(np.arange(TARGET_FACES), SAMPLES_PER_FACE)
    solid_angle = area[face_index] * cos_incidence / reach**2  # 004: "resolution constraints"
    large = solid_angle >= config.strict_min_pixels * _pixel_solid_angle(config)
    large &= reach <= config.camera_range
    candidate = np.flatnonzero(level & large)  # the cheap tests first: fewer to measure
    free = clearance(viewpoint[candidate], room.solids, room.size) >= config.robot_radius
    candidate = candidate[free]
    seen = np.zeros(len(viewpoint), dtype=bool)
    if len(candidate):  # one cast for every candidate viewpoint of the room
        _, tri = RayCaster(room.vertices, room.triangles).cast(
            viewpoint[candidate], towards[candidate], reach[candidate] + _SIGHT_SLACK
        )
        hit_face = np.where(tri >= 0, room.face_of_triangle[np.maximum(tri, 0)], -1)
        seen[candidate] = hit_face == face_index[candidate]
    return np.logical_or.reduce(seen.reshape(TARGET_FACES, SAMPLES_PER_FACE), axis=1)
