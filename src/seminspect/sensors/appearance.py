"""A colour image a detector must read: appearances drawn per world and seed, apart from the
grey intensity image.

The intensity image (:mod:`.shading`) gives every (class, part) one fixed grey level, which
keeps 000 eq (8)'s feature matching stable but would let a network learn "label = grey level".
The colour image is a separate channel with nothing fixed per label: an :class:`Appearance`
draws, from its own seed, a paint colour per object, a material per part (paint of the object,
or one of the materials below, each with its colour drawn around a base), ground and sky
colours, the sun's direction and the light's colour and brightness, and a texture of its own
(the value noise of :mod:`.shading`, seeded apart). Sensor noise comes from the caller's own
generator (:func:`add_colour_noise`). Appearances of disjoint seed ranges never share colours
or lighting, which is how a detector is tested on appearances it never saw.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field

import numba
import numpy as np
from numpy.typing import NDArray

from seminspect.sensors.shading import OCTAVE_WEIGHTS, OCTAVES, surface_tables, texture_value
from seminspect.worlds import World

#: Base colours (linear RGB in [0, 1]) of the materials a part can be made of, by the words of
#: its name; a part whose name has none of them is painted like its object.
MATERIALS = {
    "glass": ((0.12, 0.16, 0.2), ("glass", "window")),
    "rubber": ((0.06, 0.06, 0.06), ("wheel", "tyre", "tire")),
    "lamp": ((0.85, 0.8, 0.65), ("light", "lamp")),
    "roofing": ((0.3, 0.28, 0.27), ("roof",)),
}
#: How far each material's colour strays from its base (per channel, uniform).
MATERIAL_SPREAD = 0.08


@dataclass(frozen=True, eq=False)
class Appearance:
    """How one world looks in colour under one appearance seed (see the module docstring).

    Attributes:
        seed: the appearance's seed.
        instance_paint: ``(n, 3)`` paint colour per instance id (row 0: the ground's colour).
        part_colour: ``(m, 3)`` colour per part id, where the part is of a material; NaN rows
            are painted like their object.
        sky: colour of pixels that see nothing.
        sun: unit vector towards the sun.
        light: the light's colour and brightness, per channel.
        texture_seed: added to every face's texture seed, so textures differ between seeds.
    """

    seed: int
    instance_paint: NDArray[np.float64]
    part_colour: NDArray[np.float64]
    sky: NDArray[np.float64]
    sun: NDArray[np.float64]
    light: NDArray[np.float64]
    texture_seed: int
    _faces: weakref.WeakKeyDictionary[World, tuple[NDArray, NDArray]] = field(
        default_factory=weakref.WeakKeyDictionary, repr=False
    )

    @classmethod
    def draw(cls, world: World, seed: int) -> Appearance:
        """The appearance of ``world`` under ``seed`` (the same seed: the same appearance)."""
        rng = np.random.default_rng([0xC010, seed])
        instances = int(world.face_instance.max()) + 1
        paint = _hsv_to_rgb(
            rng.uniform(0, 1, instances), rng.uniform(0.15, 0.85, instances),
            rng.uniform(0.25, 0.95, instances),
        )  # fmt: skip
        paint[0] = _hsv_to_rgb(rng.uniform(0.05, 0.3, 1), rng.uniform(0, 0.35, 1),
                               rng.uniform(0.3, 0.6, 1))[0]  # fmt: skip
        elevation, azimuth = rng.uniform(0.35, 1.35), rng.uniform(0, 2 * np.pi)
        sun = np.array(
            [np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth),
             np.sin(elevation)]
        )  # fmt: skip
        warmth = rng.uniform(-0.15, 0.15)
        light = rng.uniform(0.6, 1.25) * np.array([1 + warmth, 1.0, 1 - warmth])
        sky = _hsv_to_rgb(rng.uniform(0.5, 0.7, 1), rng.uniform(0, 0.5, 1), rng.uniform(0.55, 1, 1))
        return cls(
            seed=seed,
            instance_paint=paint,
            part_colour=_part_colours(world.part_names, rng),
            sky=sky[0],
            sun=sun,
            light=light,
            texture_seed=int(rng.integers(1, 2**30)),
        )

    def face_tables(self, world: World) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Per-face colour ``(F, 3)`` and sun cosine, for :func:`shade_colour`."""
        cached = self._faces.get(world)
        if cached is None:
            colour = self.instance_paint[world.face_instance]
            material = self.part_colour[world.face_part]
            has_material = ~np.isnan(material[:, 0])
            colour[has_material] = material[has_material]
            cached = (np.ascontiguousarray(colour), world.face_normals @ self.sun)
            self._faces[world] = cached
        return cached


def _part_colours(part_names: list[str], rng: np.random.Generator) -> NDArray[np.float64]:
    colours = np.full((len(part_names), 3), np.nan)
    for index, name in enumerate(part_names):
        for base, words in MATERIALS.values():
            if any(word in name for word in words):
                spread = rng.uniform(-MATERIAL_SPREAD, MATERIAL_SPREAD, 3)
                colours[index] = np.clip(np.add(base, spread), 0.0, 1.0)
                break
    return colours


def _hsv_to_rgb(hue: NDArray, saturation: NDArray, value: NDArray) -> NDArray[np.float64]:
    """Colours from hue, saturation and value arrays, all in [0, 1]."""
    h6 = (hue % 1.0) * 6.0
    channel = np.stack([(5 + h6) % 6, (3 + h6) % 6, (1 + h6) % 6], axis=1)
    weight = np.clip(np.minimum(channel, 4 - channel), 0, 1)
    return value[:, None] * (1 - saturation[:, None] * weight)


def colour_image(
    appearance: Appearance,
    world: World,
    origin: NDArray[np.float64],
    hits: tuple[NDArray[np.float32], NDArray[np.float32], NDArray[np.int32]],
    pixel_angle: float,
) -> NDArray[np.uint8]:
    """The flat ``(n, 3)`` colour image of ray hits (directions, distances, faces)."""
    directions, distance, face = hits
    colour, sun_cosine = appearance.face_tables(world)
    _, axes, seed, _ = surface_tables(world)
    out = np.empty((len(face), 3), dtype=np.uint8)
    shade_colour(
        distance, face, directions, origin, pixel_angle, colour, sun_cosine, axes,
        seed + appearance.texture_seed, OCTAVES, OCTAVE_WEIGHTS,
        appearance.sky * 255.0, appearance.light, out,
    )  # fmt: skip
    return out


@numba.njit(cache=True, nogil=True)
def shade_colour(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    distance: np.ndarray,
    face: np.ndarray,
    directions: np.ndarray,
    origin: np.ndarray,
    pixel_angle: float,
    colour: np.ndarray,
    sun_cosine: np.ndarray,
    plane_axes: np.ndarray,
    plane_seed: np.ndarray,
    octaves: np.ndarray,
    weights: np.ndarray,
    sky: np.ndarray,
    light: np.ndarray,
    out: np.ndarray,
) -> None:
    """Lambert shading (two-sided, ambient), the texture and the light over each face's colour."""
    last_cell = np.zeros((octaves.shape[0], 3), dtype=np.int64)
    last_cell[:, 2] = -1
    last_value = np.zeros(octaves.shape[0])
    for i in range(distance.shape[0]):
        f = face[i]
        if f < 0:
            for c in range(3):
                out[i, c] = np.uint8(sky[c])
            continue
        t = distance[i]
        a = plane_axes[f, 0]
        b = plane_axes[f, 1]
        u = origin[a] + t * directions[i, a]
        v = origin[b] + t * directions[i, b]
        texture = texture_value(
            u, v, 2.0 * t * pixel_angle, plane_seed[f], octaves, weights, last_cell, last_value
        )
        shade = (0.3 + 0.7 * abs(sun_cosine[f])) * (0.6 + 0.4 * texture)
        for c in range(3):
            out[i, c] = np.uint8(min(255.0, 255.0 * colour[f, c] * light[c] * shade))


def add_colour_noise(
    image: NDArray[np.uint8], rng: np.random.Generator, sigma: float = 4.0
) -> NDArray[np.uint8]:
    """The image with Gaussian sensor noise of ``sigma`` grey levels drawn from ``rng``."""
    noisy = image.astype(np.float32) + rng.normal(0.0, sigma, image.shape).astype(np.float32)
    return np.clip(np.rint(noisy), 0, 255).astype(np.uint8)
