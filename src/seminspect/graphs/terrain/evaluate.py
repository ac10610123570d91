"""Object-layer quality against ground-truth instances: precision and recall at a box IoU."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

from seminspect.graphs.terrain.scene_graph import TerrainSceneGraph

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
