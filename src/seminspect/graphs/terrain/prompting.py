"""Layer 1 of the task-driven graph: the points relevant to the task (001 Sec III-B.1).

A task is a list of terrain prompts ("sidewalk") and object prompts ("image of a tree"). Every
point's averaged embedding is compared with every prompt by cosine similarity; a point belongs to
an object prompt when its best object similarity reaches α (Sec III-B.2), otherwise to a terrain
prompt when its best terrain similarity reaches the terrain threshold (Sec IV-C). Objects win
over terrain because a car standing on asphalt is not walkable asphalt.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.mapping.semantic_cloud import SemanticCloud
from seminspect.perception.encoders import Calibration, TextEncoder

UNCLASSIFIED = -1


@dataclass(frozen=True)
class TaskPrompts:
    """The prompts of one task: terrain types to build places on, objects to find."""

    terrain: tuple[str, ...]
    objects: tuple[str, ...]

    def __post_init__(self) -> None:
        every = [*self.terrain, *self.objects]
        if not self.terrain:
            raise InvalidInputError("give at least one terrain prompt (e.g. 'sidewalk')")
        if any(not isinstance(p, str) or not p.strip() for p in every):
            raise InvalidInputError("prompts must be non-empty text")
        if len(set(every)) != len(every):
            raise InvalidInputError(f"prompts must be distinct, got {every}")

    @classmethod
    def parse(cls, terrain: str, objects: str) -> TaskPrompts:
        """From comma-separated lists, e.g. ``"sidewalk,grass"`` and ``"image of a car"``."""

        def split(text: str) -> tuple[str, ...]:
            return tuple(p.strip() for p in text.split(",") if p.strip())

        return cls(split(terrain), split(objects))

    @property
    def all(self) -> tuple[str, ...]:
        """Terrain prompts then object prompts: the class order of :class:`TaskPoints`."""
        return (*self.terrain, *self.objects)


@dataclass
class TaskPoints:
    """Layer 1: the task-relevant points and the prompt each belongs to.

    Attributes:
        points: ``(M, 3)`` points.
        classes: ``(M,)`` index into ``prompts.all``.
        similarity: ``(M, P)`` cosine similarity of each point to every prompt.
        source: ``(M,)`` index of each point in the phase-1 cloud.
    """

    prompts: TaskPrompts
    points: NDArray[np.float64]
    classes: NDArray[np.int64]
    similarity: NDArray[np.float32]
    source: NDArray[np.int64]

    def of(self, prompt: str) -> NDArray[np.int64]:
        """Row indices of the points of one prompt."""
        return np.flatnonzero(self.classes == self.prompts.all.index(prompt))

    def counts(self) -> dict[str, int]:
        tally = np.bincount(self.classes, minlength=len(self.prompts.all))
        return {prompt: int(n) for prompt, n in zip(self.prompts.all, tally, strict=True)}


def embed_prompts(encoder: TextEncoder, prompts: Sequence[str], dim: int) -> NDArray[np.float32]:
    """Prompt embeddings, checked against the cloud's embedding size."""
    vectors = np.asarray(encoder.encode_text(list(prompts)), dtype=np.float32)
    if vectors.shape != (len(prompts), dim):
        raise InvalidInputError(
            f"encoder {encoder.name!r} gives {vectors.shape[-1]}-d prompts, the cloud is {dim}-d"
        )
    return vectors


def classes_from_similarity(
    similarity: NDArray[np.float32], n_terrain: int, calibration: Calibration
) -> NDArray[np.int64]:
    """Objects by α first, then terrain by its threshold; best prompt within each group."""
    classes = np.full(similarity.shape[0], UNCLASSIFIED, dtype=np.int64)
    if similarity.shape[1] > n_terrain:
        objects = similarity[:, n_terrain:]
        best = np.argmax(objects, axis=1)
        hit = objects[np.arange(objects.shape[0]), best] >= calibration.objects
        classes[hit] = n_terrain + best[hit]
    terrain = similarity[:, :n_terrain]
    best = np.argmax(terrain, axis=1)
    hit = (classes == UNCLASSIFIED) & (
        terrain[np.arange(terrain.shape[0]), best] >= calibration.terrain
    )
    classes[hit] = best[hit]
    return classes


def task_points(
    cloud: SemanticCloud,
    prompts: TaskPrompts,
    prompt_embeddings: NDArray[np.float32],
    calibration: Calibration,
) -> tuple[TaskPoints, NDArray[np.int64]]:
    """Layer 1 (001 Sec III-B.1): every point that matches a terrain or object prompt.

    Also returns the class of every cloud point (``UNCLASSIFIED`` where none matches).
    """
    similarity = cloud.similarity(prompt_embeddings)
    classes = classes_from_similarity(similarity, len(prompts.terrain), calibration)
    keep = np.flatnonzero(classes != UNCLASSIFIED)
    layer = TaskPoints(prompts, cloud.points[keep], classes[keep], similarity[keep], keep)
    return layer, classes
