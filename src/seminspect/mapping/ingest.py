"""Semantic clouds from labelled or embedded points (files, SemanticKITTI scans).

Labelled data stand in for 001's camera segments: in one view every point of a class belongs to
one segment, whose embedding the encoder derives from the class name (a caption). Fusing several
posed views averages these per map point exactly as camera segments are averaged
(001 Sec III-A.3), so view-to-view noise shrinks with the number of views.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import as_points
from seminspect.mapping.formats.pointfiles import PointData
from seminspect.mapping.ground import BareCloudLabels, GroundFilterParams, label_bare_cloud
from seminspect.mapping.semantic_cloud import (
    IntegrationStats,
    SemanticCloud,
    as_transform,
    transform_points,
)
from seminspect.perception.encoders import Encoder, Segment

#: Classes that carry no semantics (SemanticKITTI's "unlabeled" and "outlier").
UNLABELLED: frozenset[str] = frozenset({"unlabeled", "unlabelled", "outlier"})


def label_embeddings(
    labels: ArrayLike,
    names: Mapping[int, str],
    encoder: Encoder,
    skip: Collection[str] = UNLABELLED,
) -> tuple[NDArray[np.int64], NDArray[np.float32]]:
    """One view of labelled points: indices of the points with a meaningful class and embeddings.

    Each class present becomes one segment embedded by ``encoder.encode_segments``.
    """
    ids = np.asarray(labels).reshape(-1).astype(np.int64)
    present = np.unique(ids)
    unnamed = [int(i) for i in present if int(i) not in names]
    if unnamed:
        raise InvalidInputError(
            f"labels {unnamed[:8]} have no name; give label names (e.g. '0=ground,1=car')"
        )
    kept = np.array([i for i in present if names[int(i)] not in skip], dtype=np.int64)
    if kept.size == 0:
        return np.zeros(0, np.int64), np.zeros((0, encoder.dim), np.float32)
    rows = encoder.encode_segments([Segment(label=names[int(i)]) for i in kept])
    index = np.flatnonzero(np.isin(ids, kept))
    return index, rows[np.searchsorted(kept, ids[index])]


def cloud_from_point_data(
    data: PointData,
    encoder: Encoder,
    names: Mapping[int, str] | None = None,
    source: str | Path | None = None,
) -> SemanticCloud:
    """A single-view cloud: per-point embeddings as given, or embedded labels.

    ``source`` (the file the data came from) names it in the error lines.
    """
    where = f"{source}: " if source is not None else ""
    if data.embeddings is not None:
        if data.embeddings.shape[1] != encoder.dim:
            raise InvalidInputError(
                f"{where}the file's embeddings have {data.embeddings.shape[1]} dimensions, "
                f"encoder {encoder.name!r} makes {encoder.dim}"
            )
        counts = np.ones(data.points.shape[0], np.int64)
        return SemanticCloud(data.points, data.embeddings, counts, encoder.name)
    if data.labels is None:
        raise InvalidInputError(
            f"{where}the point file has neither per-point embeddings nor labels "
            "(label_bare_points gives a bare cloud ground and object labels)"
        )
    try:
        index, embeddings = label_embeddings(
            data.labels, {**data.label_names, **(names or {})}, encoder
        )
    except InvalidInputError as exc:
        raise InvalidInputError(f"{where}{exc}") from None
    if index.size == 0:
        raise InvalidInputError(f"{where}no point carries a meaningful label")
    return SemanticCloud(
        data.points[index], embeddings, np.ones(index.size, np.int64), encoder.name
    )


def label_bare_points(
    data: PointData,
    params: GroundFilterParams | None = None,
    seed: int = 0,
    source: str | Path | None = None,
) -> tuple[PointData, BareCloudLabels]:
    """The geometric path for a cloud without labels or embeddings: ground, object and
    outlier labels from the ground filter and the object clustering (``mapping.ground``).

    ``source`` (the file the data came from) names it in the error lines.
    """
    try:
        bare = label_bare_cloud(data.points, params, seed)
    except InvalidInputError as exc:
        raise InvalidInputError(f"{source}: {exc}" if source is not None else str(exc)) from None
    return PointData(data.points, labels=bare.labels, label_names=bare.names), bare


def integrate_labelled_scan(
    cloud: SemanticCloud,
    points_sensor: ArrayLike,
    labels: ArrayLike,
    T_world_sensor: ArrayLike,
    *,
    names: Mapping[int, str],
    encoder: Encoder,
    radius: float,
) -> IntegrationStats:
    """Fuse one posed, labelled scan into ``cloud`` as one view (001 Sec III-A.3)."""
    points = as_points(points_sensor, "scan points")
    pose = as_transform(T_world_sensor, "scan pose")
    label_array = np.asarray(labels).reshape(-1)
    if label_array.shape[0] != points.shape[0]:
        raise InvalidInputError(
            f"{label_array.shape[0]} labels for a scan of {points.shape[0]} points"
        )
    index, embeddings = label_embeddings(label_array, names, encoder)
    return cloud.integrate(transform_points(pose, points[index]), embeddings, radius)
