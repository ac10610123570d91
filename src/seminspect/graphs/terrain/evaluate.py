"""Quality of a terrain scene graph against ground truth (001 Sec IV, where truth is known).

- Objects: predicted boxes matched one-to-one with true boxes; precision and recall at a box IoU.
- Places: for each true patch of a terrain, whether its places form one connected GVD graph,
  and whether any place lies off every patch of its terrain.
- A prompt is scored against the ground-truth class it names: a class whose name it is (after
  dropping "image of a"), else the one class it names by a synonym of the caption vocabulary,
  else the class whose caption the encoder finds most similar, when that similarity reaches the
  prompt's threshold. Text similarity alone would score 'trunk' against whatever caption its
  embedding happens to sit nearest; the chosen class, how it was chosen and its similarity are
  reported beside the scores.

:class:`ObjectQuality`, :class:`PlaceQuality` and :class:`TerrainQuality` hold these scores per
prompt; their ``to_json`` gives the records of a run's ``summary.json``.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import Any, Literal

import networkx as nx
import numpy as np
import shapely
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment
from shapely.geometry import Polygon

from seminspect.core.io import finite_or_none
from seminspect.graphs.terrain.scene_graph import TerrainSceneGraph
from seminspect.perception.encoders import DEFAULT_SYNONYMS, TextEncoder, caption

Box = tuple[NDArray[np.float64], NDArray[np.float64]]


@dataclass(frozen=True)
class ObjectScores:
    """Detections matched one-to-one with ground truth at ``IoU >= threshold``."""

    threshold: float
    predicted: int
    ground_truth: int
    matched: int
    mean_iou: float  # over the matched pairs

    @property
    def precision(self) -> float:
        return self.matched / self.predicted if self.predicted else 0.0

    @property
    def recall(self) -> float:
        return self.matched / self.ground_truth if self.ground_truth else 0.0

    def to_json(self) -> dict[str, Any]:
        return {
            "iou_threshold": self.threshold,
            "predicted": self.predicted,
            "ground_truth": self.ground_truth,
            "matched": self.matched,
            "precision": self.precision,
            "recall": self.recall,
            "mean_iou": self.mean_iou,
        }


def box_iou(first: Box, second: Box) -> float:
    """Intersection over union of two axis-aligned 3D boxes ``(min corner, max corner)``."""
    low = np.maximum(first[0], second[0])
    high = np.minimum(first[1], second[1])
    inter = float(np.prod(np.clip(high - low, 0.0, None)))
    union = float(np.prod(first[1] - first[0]) + np.prod(second[1] - second[0])) - inter
    return inter / union if union > 0 else 0.0


def match_boxes(predicted: list[Box], truth: list[Box], threshold: float = 0.3) -> ObjectScores:
    """Optimal one-to-one assignment (Hungarian) on IoU; pairs below ``threshold`` do not count."""
    if not predicted or not truth:
        return ObjectScores(threshold, len(predicted), len(truth), 0, 0.0)
    iou = np.array([[box_iou(p, t) for t in truth] for p in predicted])
    rows, cols = linear_sum_assignment(-iou)
    good = iou[rows, cols] >= threshold
    mean = float(iou[rows, cols][good].mean()) if good.any() else 0.0
    return ObjectScores(threshold, len(predicted), len(truth), int(good.sum()), mean)


def predicted_boxes(scene: TerrainSceneGraph, prompt: str) -> list[Box]:
    """Bounding boxes of the object nodes of one prompt."""
    graph = scene.graph
    return [
        (graph.nodes[n]["bbox_min"], graph.nodes[n]["bbox_max"])
        for n in scene.nodes_of("object")
        if graph.nodes[n]["label"] == prompt
    ]


#: Words around an object prompt that name no class ("image of a tree").
_PROMPT_FILLER = re.compile(r"^(an? )?(image|photo|picture) of (an? |the )?")


def prompt_name(prompt: str) -> str:
    """The class name a prompt spells: lower case, filler dropped, dashes as spaces."""
    words = " ".join(prompt.lower().replace("-", " ").replace("_", " ").split())
    return _PROMPT_FILLER.sub("", words)


@dataclass(frozen=True)
class ClassMatch:
    """The ground-truth class a prompt is scored against, and how it was chosen.

    Attributes:
        truth: the class, or ``None`` when the prompt names none and no caption is similar
            enough.
        by: ``"name"`` (the prompt is the class's name), ``"alias"`` (a synonym of exactly one
            class), ``"similarity"`` (the most similar caption) or ``"none"``.
        similarity: cosine similarity of the prompt to the chosen (or, for ``"none"``, the most
            similar) class's caption; ``None`` without classes.
    """

    truth: str | None
    by: Literal["name", "alias", "similarity", "none"]
    similarity: float | None

    def to_json(self) -> dict[str, Any]:
        return {
            "ground_truth_class": self.truth,
            "class_chosen_by": self.by,
            "class_similarity": self.similarity,
        }


def match_class(
    encoder: TextEncoder,
    prompt: str,
    classes: Sequence[str],
    threshold: float,
    synonyms: Mapping[str, Sequence[str]] = DEFAULT_SYNONYMS,
) -> ClassMatch:
    """The class of ``classes`` that ``prompt`` names: by name, by one class's synonym, or by
    caption similarity of at least ``threshold`` (see the module docstring)."""
    if not classes:
        return ClassMatch(None, "none", None)
    captions = encoder.encode_text([caption(name, synonyms) for name in classes])
    similarity = captions @ encoder.encode_text([prompt])[0]
    name = prompt_name(prompt)
    by: Literal["name", "alias", "similarity", "none"]
    named = [i for i, c in enumerate(classes) if c.replace("-", " ") == name]
    aliased = [i for i, c in enumerate(classes) if name in synonyms.get(c, ())]
    if named:
        best, by = named[0], "name"
    elif len(aliased) == 1:
        best, by = aliased[0], "alias"
    else:  # among the classes a shared synonym names, or all of them
        candidates = aliased or range(len(classes))
        best = max(candidates, key=lambda i: float(similarity[i]))
        by = "similarity" if similarity[best] >= threshold else "none"
    score = float(similarity[best])
    return ClassMatch(classes[best] if by != "none" else None, by, score)


@dataclass(frozen=True)
class PlaceScores:
    """The places of one terrain prompt against the true patches of its class.

    Attributes:
        terrain: the terrain prompt.
        patches: true patches of at least the minimum area (the ones scored).
        with_places: of those, patches that hold at least one place.
        connected: of those, patches whose places form one graph over ``gvd`` edges.
        places: places of the prompt.
        off_terrain: places farther than the tolerance from every patch of the class.
        worst_offset: the largest distance of a place from the class's patches (0: inside;
            infinite when the world has no patch of the class).
    """

    terrain: str
    patches: int
    with_places: int
    connected: int
    places: int
    off_terrain: int
    worst_offset: float

    @property
    def all_connected(self) -> bool:
        """Every scored patch got a connected place graph."""
        return self.connected == self.patches

    def to_json(self) -> dict[str, Any]:
        record = {**asdict(self), "all_connected": self.all_connected}
        return {**record, "worst_offset": finite_or_none(self.worst_offset)}


def score_places(
    scene: TerrainSceneGraph,
    terrain: str,
    patches: Sequence[Polygon],
    *,
    min_area: float = 10.0,
    tolerance: float = 0.5,
) -> PlaceScores:
    """Score the places of ``terrain`` against the true ``patches`` of its class.

    A place belongs to the patch it lies in (within ``tolerance``, half a grid cell or so, since
    places sit at cell centres); patches smaller than ``min_area`` square metres are not scored.
    """
    graph = scene.graph
    places = [n for n in scene.nodes_of("place") if graph.nodes[n]["terrain"] == terrain]
    xy = np.array([graph.nodes[n]["position"][:2] for n in places]).reshape(-1, 2)
    points = shapely.points(xy)
    offsets = (
        shapely.distance(shapely.union_all(list(patches)), points)
        if patches
        else np.full(len(places), np.inf)  # the world has no such terrain
    )
    scored = [p for p in patches if p.area >= min_area]
    with_places = connected = 0
    for patch in scored:
        zone = patch.buffer(tolerance)
        inside = [n for n, point in zip(places, points, strict=True) if zone.contains(point)]
        if not inside:
            continue
        with_places += 1
        links = nx.Graph()
        links.add_nodes_from(inside)
        links.add_edges_from(
            (a, b) for a, b, kind in graph.subgraph(inside).edges(data="kind") if kind == "gvd"
        )
        connected += int(nx.is_connected(links))
    return PlaceScores(
        terrain=terrain,
        patches=len(scored),
        with_places=with_places,
        connected=connected,
        places=len(places),
        off_terrain=int(np.sum(offsets > tolerance)),
        worst_offset=float(offsets.max(initial=0.0)),
    )


@dataclass(frozen=True)
class ObjectQuality:
    """An object prompt's ground-truth class and its detections' scores against that class.

    Attributes:
        match: the class the prompt is scored against.
        scores: precision and recall, or ``None`` when the truth cannot score the class.
        unscored: why a chosen class was not scored (the truth has no instances of it).
    """

    match: ClassMatch
    scores: ObjectScores | None = None
    unscored: str | None = None

    def to_json(self) -> dict[str, Any]:
        record = self.match.to_json()
        if self.unscored is not None:
            record["unscored"] = self.unscored
        if self.scores is not None:
            record.update(self.scores.to_json())
        return record


@dataclass(frozen=True)
class PlaceQuality:
    """A terrain prompt's ground-truth class and how its points and places lie on that class.

    Attributes:
        match: the class the prompt is scored against.
        points_on_terrain: share of the prompt's layer-1 points on a true patch of the class;
            ``None`` without layer-1 points of the prompt.
        scores: the prompt's places against the class's patches.
    """

    match: ClassMatch
    points_on_terrain: float | None
    scores: PlaceScores

    def to_json(self) -> dict[str, Any]:
        return {
            **self.match.to_json(),
            "points_on_terrain": self.points_on_terrain,
            **self.scores.to_json(),
        }


@dataclass(frozen=True)
class TerrainQuality:
    """A terrain scene graph scored against a world's truth, per object and terrain prompt."""

    objects: dict[str, ObjectQuality]
    places: dict[str, PlaceQuality]

    def to_json(self) -> dict[str, Any]:
        return {
            "objects": {prompt: q.to_json() for prompt, q in self.objects.items()},
            "places": {prompt: q.to_json() for prompt, q in self.places.items()},
        }
