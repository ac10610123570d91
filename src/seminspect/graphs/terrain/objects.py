"""Layer 2: object nodes from prompted points (001 Sec III-B.2).

The points of each object prompt (similarity above α, see ``prompting``) are clustered by
DBSCAN; every cluster becomes one object node with its axis-aligned bounding box, label and point
count. For speed the points are first gathered into small voxels and DBSCAN runs on the voxel
centroids weighted by their point counts (``sample_weight``), which keeps ``min_samples`` a count
of points; every point then takes its voxel's cluster.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from seminspect.graphs.terrain.prompting import TaskPoints


@dataclass(frozen=True)
class ObjectCluster:
    """One detected object."""

    label: str
    centroid: NDArray[np.float64]
    bbox_min: NDArray[np.float64]
    bbox_max: NDArray[np.float64]
    n_points: int
    score: float  # mean similarity of its points to the prompt
    members: NDArray[np.int64]  # rows of the layer-1 points


def voxel_groups(
    points: NDArray[np.float64], voxel: float
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]:
    """Voxel centroids, the voxel of each point and the number of points per voxel."""
    keys = np.floor(points / voxel).astype(np.int64)
    _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    sums = np.zeros((counts.size, 3))
    for axis in range(3):
        sums[:, axis] = np.bincount(inverse, weights=points[:, axis], minlength=counts.size)
    return sums / counts[:, None], inverse, counts


def cluster_points(
    points: NDArray[np.float64], eps: float, min_points: int, voxel: float
) -> NDArray[np.int64]:
    """DBSCAN cluster id of each point (-1 = noise), on count-weighted voxel centroids."""
    if points.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    # Loaded here: every mission imports this module, few of them cluster terrain objects.
    from sklearn.cluster import DBSCAN  # noqa: PLC0415 - a second and a half to import

    centroids, inverse, counts = voxel_groups(points, voxel)
    labels = DBSCAN(eps=eps, min_samples=min_points).fit(centroids, sample_weight=counts).labels_
    return labels[inverse].astype(np.int64)


def extract_objects(
    layer: TaskPoints, eps: float, min_points: int, voxel: float
) -> list[ObjectCluster]:
    """Object clusters for every object prompt, in prompt order then by size (largest first)."""
    found: list[ObjectCluster] = []
    for prompt_index, prompt in enumerate(layer.prompts.objects):
        rows = layer.of(prompt)
        if rows.size == 0:
            continue
        labels = cluster_points(layer.points[rows], eps, min_points, voxel)
        column = len(layer.prompts.terrain) + prompt_index
        clusters = []
        # one stable sort instead of a pass over every point per cluster (thousands at 1 M points)
        order = np.argsort(labels, kind="stable")
        ids, starts = np.unique(labels[order], return_index=True)
        for cluster, members in zip(ids, np.split(rows[order], starts[1:]), strict=True):
            if cluster < 0:
                continue  # DBSCAN's noise
            pts = layer.points[members]
            clusters.append(
                ObjectCluster(
                    label=prompt,
                    centroid=pts.mean(axis=0),
                    bbox_min=pts.min(axis=0),
                    bbox_max=pts.max(axis=0),
                    n_points=int(members.size),
                    score=float(layer.similarity[members, column].mean()),
                    members=members,
                )
            )
        found.extend(sorted(clusters, key=lambda c: (-c.n_points, tuple(c.centroid))))
    return found
