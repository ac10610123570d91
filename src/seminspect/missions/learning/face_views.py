"""What the camera saw of each target face: per step, and kept over an episode.

The face reward (004 eqs (7)-(9)) and the coverage measures start from the same statistics of
each target face over its pixels in the focus area (004 Sec III-C): the pixel count, the mean
range and the mean incidence. :class:`FaceRecord` keeps, per room and face, the best view
distance d_f (eq (8)) and whether the strict rule was met once; the strict rule is a measure
only: no reward uses it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.rewards import (
    distance_score,
    face_scores,
    inspected_fraction,
    shaped_fraction,
    shaping_forfeit,
    updated_best,
)
from seminspect.missions.learning.rooms import TARGET_FACES


@dataclass(frozen=True)
class FaceViews:
    """Per ``(row, face)`` of one step: focus-area pixels, mean range (m) and mean incidence
    (deg); the means are nan for faces not in view."""

    count: NDArray[np.int64]
    distance: NDArray[np.float64]
    incidence: NDArray[np.float64]


def triangle_normals(vertices: NDArray, triangles: NDArray) -> NDArray[np.float64]:
    """Unit normal of each triangle (zero for degenerate ones), from its corners' winding."""
    corner = np.asarray(vertices, dtype=np.float64)[np.asarray(triangles)]
    normal = np.cross(corner[:, 1] - corner[:, 0], corner[:, 2] - corner[:, 0])
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    return np.divide(normal, length, out=np.zeros_like(normal), where=length > 0)


def incidence_degrees(normals: NDArray[np.float64], dirs: NDArray) -> NDArray[np.float64]:
    """Angle between each hit triangle's normal and the reversed ray (0: head-on).

    Taken unsigned, so it does not depend on the winding: a camera sees a closed target's
    faces from outside only, where that is the angle to the outward normal.
    """
    cosine = np.abs(np.einsum("ij,ij->i", normals, np.asarray(dirs, dtype=np.float64)))
    return np.degrees(np.arccos(np.clip(cosine, 0.0, 1.0)))


def face_views(
    key: NDArray[np.int64], distance: NDArray, incidence: NDArray, size: int
) -> FaceViews:
    """Aggregate focus-area pixels by ``key`` = row * faces + face over ``size`` keys (flat)."""
    count = np.bincount(key, minlength=size)
    total = np.bincount(key, weights=distance, minlength=size)
    mean = np.divide(total, count, out=np.full(size, np.nan), where=count > 0)
    turned = np.bincount(key, weights=incidence, minlength=size)
    angle = np.divide(turned, count, out=np.full(size, np.nan), where=count > 0)
    return FaceViews(count, mean, angle)


def strict_views(
    views: FaceViews, d_ref: float, band: float, incidence_deg: float, min_pixels: int
) -> NDArray[np.bool_]:
    """Faces seen well this step: at least ``min_pixels`` focus-area pixels, mean range within
    ``d_ref +- band`` and mean incidence at most ``incidence_deg``."""
    enough = views.count >= min_pixels
    in_band = np.abs(views.distance - d_ref) <= band
    facing = views.incidence <= incidence_deg
    return enough & in_band & facing


class FaceRecord:
    """Per room and target face: d_f (inf: never seen in the focus area) and strictly seen;
    per room the last f_t (the potential of a shaped reward)."""

    def __init__(self, rooms: int, config: EnvConfig) -> None:
        self.config = config
        self.best = np.full((rooms, TARGET_FACES), np.inf)
        self.strict = np.zeros((rooms, TARGET_FACES), dtype=bool)
        self.fraction = np.zeros(rooms)

    def clear(self, envs: NDArray[np.int64]) -> None:
        self.best[envs] = np.inf
        self.strict[envs] = False
        self.fraction[envs] = 0.0

    def update(self, envs: NDArray[np.int64], views: FaceViews) -> NDArray[np.float64]:
        """Take in one step's views of the rooms ``envs``; returns their f_t (eq (9)) as paid
        (shaped with :attr:`EnvConfig.shaping_discount`)."""
        cfg = self.config
        mean, best = views.distance.reshape(len(envs), -1), self.best[envs]
        if cfg.face_reward == "repaid":
            scores, self.best[envs] = face_scores(mean, best, cfg.d_ref, cfg.alpha, cfg.beta)
            f_t = scores.sum(axis=1)
        else:
            self.best[envs] = updated_best(mean, best, cfg.d_ref)
            f_t = inspected_fraction(self.best[envs], cfg.d_ref, cfg.beta)
            if cfg.shaping_discount is not None:
                previous, self.fraction[envs] = self.fraction[envs], f_t
                f_t = shaped_fraction(f_t, previous, cfg.shaping_discount)
        rule = cfg.strict_band, cfg.strict_incidence_deg, cfg.strict_min_pixels
        self.strict[envs] |= strict_views(views, cfg.d_ref, *rule).reshape(len(envs), -1)
        return f_t

    def crash_forfeit(self, envs: NDArray[np.int64]) -> NDArray[np.float64]:
        """What a crash of the rooms ``envs`` costs beyond their step's pay: the shaped stream's
        potential (:func:`.rewards.shaping_forfeit`); nothing for an unshaped reward."""
        discount = self.config.shaping_discount
        if discount is None:
            return np.zeros(len(envs))
        return shaping_forfeit(self.fraction[envs], discount)

    def distance_scores(self) -> NDArray[np.float64]:
        """s(d_f) per room and face: the best distance score of any focus-area view."""
        return distance_score(self.best, self.config.d_ref, self.config.beta)
