"""The task-agnostic metric-semantic point cloud of 001 Sec III-A.

Every map point carries a semantic embedding that is the running mean of every view that saw it,
and the number of views averaged. A posed scan is fused in three steps (001 Sec III-A.3):

1. the scan is projected into a time-synchronised camera segmentation (intrinsics ``K``,
   extrinsics ``T_camera_sensor``), and each point takes the embedding of the segment it falls in;
2. a KD-tree over the map points associates each scan point with the nearest map point within a
   radius (scan points without a partner become new map points);
3. the embeddings of associated points are averaged into the map point's running mean.

Frames: ``T_a_b`` is a 4x4 rigid transform that maps coordinates in frame ``b`` into frame ``a``.
The camera frame is the optical one of OpenCV: x right, y down, z forward.

001 Sec IV-B notes that segment borders bleed onto the scenery behind an object when the LiDAR
and the camera see past an edge differently. When the camera gives a depth image (001's OAK-D is
a stereo depth camera), :class:`CameraSegmentation` can carry it, and a scan point whose depth in
the camera disagrees with the pixel's by more than ``depth_tolerance + depth_tolerance_per_m *
depth`` is occluded in that view and takes no embedding from it.
"""

from __future__ import annotations

import json
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.sparse import csr_matrix
from scipy.spatial import cKDTree

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import dumps_json, save_npz_atomic
from seminspect.geometry.transforms import as_points

CLOUD_FORMAT = "seminspect-semantic-cloud"
CLOUD_VERSION = 1
#: Rows per block when comparing embeddings with prompts, to bound temporary memory.
_SIMILARITY_BLOCK = 1 << 17


def as_transform(value: ArrayLike, what: str = "pose") -> NDArray[np.float64]:
    """A finite rigid 4x4 transform, or :class:`InvalidInputError`."""
    try:
        matrix = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{what} must be a 4x4 matrix of numbers") from None
    if matrix.shape != (4, 4):
        raise InvalidInputError(f"{what} must be 4x4, got shape {matrix.shape}")
    if not np.all(np.isfinite(matrix)):
        raise InvalidInputError(f"{what} contains NaN or infinite entries")
    rotation = matrix[:3, :3]
    if not np.allclose(matrix[3], [0.0, 0.0, 0.0, 1.0], atol=1e-6) or not np.allclose(
        rotation @ rotation.T, np.eye(3), atol=1e-4
    ):
        raise InvalidInputError(f"{what} is not a rigid transform (rotation + translation)")
    return matrix


def transform_points(transform: NDArray[np.float64], points: NDArray[np.float64]) -> NDArray:
    """Apply a 4x4 transform to ``(N, 3)`` points."""
    return points @ transform[:3, :3].T + transform[:3, 3]


@dataclass(frozen=True)
class IntegrationStats:
    """What one fusion step did: scan points averaged into map points, and map points added."""

    associated: int
    added: int


class SemanticCloud:
    """A metric-semantic point cloud (001 Sec III-A).

    Attributes:
        points: ``(N, 3)`` map points, metres in the world frame.
        embeddings: ``(N, d)`` float32 running mean of the embeddings of every view of the point.
        counts: ``(N,)`` number of observations averaged into each point.
        encoder: name of the embedding space (prompts must be embedded by the same encoder).
        source: where the cloud came from, JSON-serialisable (e.g. the simulated world, its
            scenario and seed, so that it can be scored against that world's ground truth).

    The arrays are views of buffers that grow geometrically, so fusing many scans costs time in
    proportion to the points added, not to the size of the map times the number of scans.
    """

    def __init__(
        self,
        points: ArrayLike,
        embeddings: ArrayLike,
        counts: ArrayLike,
        encoder: str,
        source: dict[str, Any] | None = None,
    ) -> None:
        self._points = as_points(points, "cloud points", allow_empty=True)
        self._embeddings = np.asarray(embeddings, dtype=np.float32)
        self._counts = np.asarray(counts, dtype=np.int64)
        self._size = n = self._points.shape[0]
        if self._embeddings.ndim != 2 or self._embeddings.shape[0] != n:
            raise InvalidInputError(
                f"cloud embeddings must have shape ({n}, d), got {self._embeddings.shape}"
            )
        if self._counts.shape != (n,) or np.any(self._counts < 0):
            raise InvalidInputError(f"cloud counts must be {n} non-negative integers")
        if not np.all(np.isfinite(self._embeddings)):
            raise InvalidInputError("cloud embeddings contain NaN or infinite values")
        if source is not None and not isinstance(source, dict):
            raise InvalidInputError("a cloud's source must be a dict")
        self.encoder = encoder
        self.source: dict[str, Any] = dict(source or {})

    @property
    def points(self) -> NDArray[np.float64]:
        return self._points[: self._size]

    @property
    def embeddings(self) -> NDArray[np.float32]:
        return self._embeddings[: self._size]

    @property
    def counts(self) -> NDArray[np.int64]:
        return self._counts[: self._size]

    def _append(self, points: NDArray[np.float64], embeddings: NDArray[np.float32]) -> None:
        """Add new map points with one observation each, growing the buffers by half if full."""
        end = self._size + points.shape[0]
        if end > self._points.shape[0]:
            capacity = max(end, self._points.shape[0] * 3 // 2, 1024)
            self._points = _grown(self._points, self._size, capacity)
            self._embeddings = _grown(self._embeddings, self._size, capacity)
            self._counts = _grown(self._counts, self._size, capacity)
        self._points[self._size : end] = points
        self._embeddings[self._size : end] = embeddings
        self._counts[self._size : end] = 1
        self._size = end

    @classmethod
    def empty(cls, dim: int, encoder: str) -> SemanticCloud:
        if dim <= 0:
            raise InvalidInputError(f"embedding dimension must be positive, got {dim}")
        return cls(np.zeros((0, 3)), np.zeros((0, dim), np.float32), np.zeros(0, np.int64), encoder)

    def __len__(self) -> int:
        return self.points.shape[0]

    @property
    def dim(self) -> int:
        return self.embeddings.shape[1]

    def integrate(
        self, points: ArrayLike, embeddings: ArrayLike, radius: float
    ) -> IntegrationStats:
        """Fuse world-frame points with one embedding each (one view), 001 Sec III-A.3.

        Each point joins the nearest map point within ``radius`` (KD-tree) and is averaged into
        its running mean, ``mean += (sum of new - k * mean) / (count + k)`` for ``k`` new
        observations; points with no map point in reach are appended with count 1.
        """
        if not (np.isfinite(radius) and radius > 0):
            raise InvalidInputError(f"association radius must be > 0, got {radius}")
        new_points = as_points(points, "scan points", allow_empty=True)
        new_embeddings = np.asarray(embeddings, dtype=np.float32)
        if new_embeddings.shape != (new_points.shape[0], self.dim):
            raise InvalidInputError(
                f"scan embeddings must have shape ({new_points.shape[0]}, {self.dim}), "
                f"got {new_embeddings.shape}"
            )
        if not np.all(np.isfinite(new_embeddings)):
            raise InvalidInputError("scan embeddings contain NaN or infinite values")
        target = self._associate(new_points, radius)
        matched = target >= 0
        self._average_into(target[matched], new_embeddings[matched])
        fresh = ~matched
        self._append(new_points[fresh], new_embeddings[fresh])
        return IntegrationStats(associated=int(matched.sum()), added=int(fresh.sum()))

    def _associate(self, points: NDArray[np.float64], radius: float) -> NDArray[np.int64]:
        """Index of the nearest map point within ``radius`` for each point, or -1.

        Only map points inside the scan's box grown by ``radius`` can be partners, so the tree
        is built over those alone: a scan covers a small part of a large map.
        """
        if len(self) == 0 or points.shape[0] == 0:
            return np.full(points.shape[0], -1, dtype=np.int64)
        low, high = points.min(axis=0) - radius, points.max(axis=0) + radius
        near = np.flatnonzero(np.all((self.points >= low) & (self.points <= high), axis=1))
        if near.size == 0:
            return np.full(points.shape[0], -1, dtype=np.int64)
        _, index = cKDTree(self.points[near]).query(points, k=1, distance_upper_bound=radius)
        found = index < near.size
        return np.where(found, near[np.where(found, index, 0)], -1).astype(np.int64)

    def _average_into(self, target: NDArray[np.int64], embeddings: NDArray[np.float32]) -> None:
        if target.size == 0:
            return
        touched, inverse, added = np.unique(target, return_inverse=True, return_counts=True)
        # Each map point's sum of new rows as one sparse product (10x np.add.reduceat's speed).
        rows = np.arange(target.size)
        ones = np.ones(target.size, dtype=np.float32)
        member = csr_matrix((ones, (inverse, rows)), shape=(touched.size, target.size))
        sums = (member @ embeddings).astype(np.float64)
        old = self._counts[touched]
        total = old + added
        mean = self._embeddings[touched].astype(np.float64)
        self._embeddings[touched] = ((mean * old[:, None] + sums) / total[:, None]).astype(
            np.float32
        )
        self._counts[touched] = total

    def similarity(self, prompts: ArrayLike) -> NDArray[np.float32]:
        """Cosine similarity ``(N, P)`` of every point's mean embedding with unit prompt rows."""
        prompt_rows = np.asarray(prompts, dtype=np.float32)
        if prompt_rows.ndim != 2 or prompt_rows.shape[1] != self.dim:
            raise InvalidInputError(
                f"prompt embeddings must have shape (P, {self.dim}), got {prompt_rows.shape}"
            )
        norms = np.linalg.norm(prompt_rows, axis=1)
        unit = prompt_rows / np.where(norms > 0, norms, 1.0)[:, None]
        out = np.empty((len(self), unit.shape[0]), dtype=np.float32)
        for start in range(0, len(self), _SIMILARITY_BLOCK):
            block = self.embeddings[start : start + _SIMILARITY_BLOCK]
            lengths = np.sqrt(np.einsum("ij,ij->i", block, block))
            dots = block @ unit.T
            out[start : start + block.shape[0]] = (
                dots / np.where(lengths > 0, lengths, 1.0)[:, None]
            )
        return out


def _grown(array: NDArray, used: int, capacity: int) -> NDArray:
    """A buffer of ``capacity`` rows holding the first ``used`` rows of ``array``."""
    grown = np.empty((capacity, *array.shape[1:]), dtype=array.dtype)
    grown[:used] = array[:used]
    return grown


@dataclass(frozen=True)
class CameraSegmentation:
    """A segmented camera image ready for fusion (001 Sec III-A.2).

    Attributes:
        segment_ids: ``(H, W)`` integer image; pixel value ``s`` is segment ``s``, -1 is none.
        embeddings: ``(S, d)`` embedding of each segment.
        K: ``3x3`` pinhole intrinsics.
        T_camera_sensor: extrinsic calibration mapping scan (sensor) coordinates into the camera.
        depth: optional ``(H, W)`` depth along the optical axis per pixel (``inf``: nothing);
            with it, scan points the camera cannot see (occluded) are not fused.
        depth_tolerance, depth_tolerance_per_m: a scan point is visible in a pixel when its
            depth is within ``depth_tolerance + depth_tolerance_per_m * depth`` of the pixel's
            (metres; the second term absorbs the depth spread of one pixel at grazing angles).
    """

    segment_ids: NDArray[np.integer]
    embeddings: NDArray[np.float32]
    K: NDArray[np.float64]
    T_camera_sensor: NDArray[np.float64]
    depth: NDArray[np.float32] | None = None
    depth_tolerance: float = 0.2
    depth_tolerance_per_m: float = 0.05

    def __post_init__(self) -> None:
        ids = np.asarray(self.segment_ids)
        if ids.ndim != 2 or not np.issubdtype(ids.dtype, np.integer):
            raise InvalidInputError("segment_ids must be a 2D integer image")
        embeddings = np.asarray(self.embeddings, dtype=np.float32)
        if embeddings.ndim != 2 or not np.all(np.isfinite(embeddings)):
            raise InvalidInputError("segment embeddings must be a finite (S, d) array")
        if ids.size and ids.max() >= embeddings.shape[0]:
            raise InvalidInputError(
                f"segment id {int(ids.max())} has no embedding ({embeddings.shape[0]} given)"
            )
        K = np.asarray(self.K, dtype=np.float64)
        if K.shape != (3, 3) or not np.all(np.isfinite(K)) or K[0, 0] <= 0 or K[1, 1] <= 0:
            raise InvalidInputError("K must be a finite 3x3 intrinsic matrix with fx, fy > 0")
        if self.depth is not None:
            depth = np.asarray(self.depth, dtype=np.float32)
            if depth.shape != ids.shape or np.isnan(depth).any():
                raise InvalidInputError(
                    f"the depth image must be a NaN-free {ids.shape} image, got {depth.shape}"
                )
            object.__setattr__(self, "depth", depth)
        tolerances = (self.depth_tolerance, self.depth_tolerance_per_m)
        if not all(np.isfinite(t) and t >= 0 for t in tolerances):
            raise InvalidInputError(f"depth tolerances must be finite and >= 0, got {tolerances}")
        object.__setattr__(self, "segment_ids", ids)
        object.__setattr__(self, "embeddings", embeddings)
        object.__setattr__(self, "K", K)
        object.__setattr__(
            self, "T_camera_sensor", as_transform(self.T_camera_sensor, "T_camera_sensor")
        )


def project_to_pixels(
    points_camera: NDArray[np.float64], K: NDArray[np.float64], shape: tuple[int, int], near: float
) -> tuple[NDArray[np.bool_], NDArray[np.int64], NDArray[np.int64]]:
    """Pinhole projection: which points land in a ``shape = (H, W)`` image, and their rows/cols."""
    depth = points_camera[:, 2]
    in_front = depth > near
    safe = np.where(in_front, depth, 1.0)
    uvw = points_camera @ K.T
    cols = np.floor(uvw[:, 0] / safe).astype(np.int64)
    rows = np.floor(uvw[:, 1] / safe).astype(np.int64)
    inside = in_front & (cols >= 0) & (cols < shape[1]) & (rows >= 0) & (rows < shape[0])
    return inside, np.where(inside, rows, 0), np.where(inside, cols, 0)


def label_scan(
    points_sensor: ArrayLike, segmentation: CameraSegmentation, near: float = 0.1
) -> tuple[NDArray[np.int64], NDArray[np.float32]]:
    """Indices of the scan points that fall in a segment, and those segments' embeddings.

    With a depth image, points hidden from the camera (their depth disagrees with the pixel's)
    count as outside every segment.
    """
    points = as_points(points_sensor, "scan points", allow_empty=True)
    in_camera = transform_points(segmentation.T_camera_sensor, points)
    inside, rows, cols = project_to_pixels(
        in_camera, segmentation.K, segmentation.segment_ids.shape, near
    )
    if segmentation.depth is not None:
        depth = in_camera[:, 2]
        seen = segmentation.depth[rows, cols]
        tolerance = segmentation.depth_tolerance + segmentation.depth_tolerance_per_m * depth
        inside &= np.abs(seen - depth) <= tolerance
    segment = np.where(inside, segmentation.segment_ids[rows, cols], -1)
    hit = np.flatnonzero(segment >= 0)
    return hit, segmentation.embeddings[segment[hit]]


def fuse_scan(
    cloud: SemanticCloud,
    points_sensor: ArrayLike,
    T_world_sensor: ArrayLike,
    segmentation: CameraSegmentation,
    *,
    radius: float,
    near: float = 0.1,
) -> IntegrationStats:
    """Fuse one posed LiDAR scan and its synchronised camera segmentation (001 Sec III-A.3).

    Scan points outside the image, behind the camera or on unsegmented pixels carry no semantics
    from this view and are not fused.
    """
    if segmentation.embeddings.shape[1] != cloud.dim:
        raise InvalidInputError(
            f"segment embeddings have {segmentation.embeddings.shape[1]} dimensions, "
            f"the cloud {cloud.dim}"
        )
    pose = as_transform(T_world_sensor, "T_world_sensor")
    points = as_points(points_sensor, "scan points", allow_empty=True)
    hit, embeddings = label_scan(points, segmentation, near)
    return cloud.integrate(transform_points(pose, points[hit]), embeddings, radius)


def save_cloud(path: str | Path, cloud: SemanticCloud) -> Path:
    """Write a cloud as a compressed ``.npz`` (atomically), its source record as JSON."""
    try:
        source = dumps_json(cloud.source)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"the cloud's source record is not JSON: {exc}") from None
    return save_npz_atomic(
        path,
        format=np.array(CLOUD_FORMAT),
        version=np.array(CLOUD_VERSION),
        points=cloud.points,
        embeddings=cloud.embeddings,
        counts=cloud.counts,
        encoder=np.array(cloud.encoder),
        source=np.array(source),
    )


def is_cloud_file(arrays: dict[str, NDArray]) -> bool:
    """Whether the arrays of an ``.npz`` carry the semantic-cloud envelope."""
    return "format" in arrays and str(arrays["format"]) == CLOUD_FORMAT


def read_npz(path: str | Path) -> dict[str, NDArray]:
    """Every array of an ``.npz`` (no pickles), or :class:`FileFormatError`."""
    source = Path(path)
    if source.is_dir():
        raise FileFormatError(f"{source}: is a directory, expected an .npz file")
    if not source.is_file():
        raise FileFormatError(f"{source}: no such file")
    try:
        with np.load(source, allow_pickle=False) as archive:
            return {key: archive[key] for key in archive.files}
    except (zipfile.BadZipFile, ValueError, OSError, EOFError, KeyError) as exc:
        raise FileFormatError(f"{source}: not a readable .npz archive ({exc})") from None


def cloud_from_arrays(source: Path, arrays: dict[str, NDArray]) -> SemanticCloud:
    """Validate the arrays of a saved cloud into a :class:`SemanticCloud`."""
    version = arrays.get("version")
    # a whole-number scalar only: a string or float "version" is not one seminspect wrote
    if version is None:
        raise FileFormatError(f"{source}: semantic cloud has no version")
    exact = version.shape == () and version.dtype.kind in "iu"
    if not exact or int(version) != CLOUD_VERSION:
        found = version.tolist()
        raise FileFormatError(f"{source}: semantic cloud version {found!r} is not supported")
    missing = [key for key in ("points", "embeddings", "counts", "encoder") if key not in arrays]
    if missing:
        raise FileFormatError(f"{source}: semantic cloud lacks {', '.join(missing)}")
    provenance = _provenance(source, arrays)
    try:
        return SemanticCloud(
            arrays["points"],
            arrays["embeddings"],
            arrays["counts"],
            str(arrays["encoder"]),
            provenance,
        )
    except InvalidInputError as exc:
        raise FileFormatError(f"{source}: {exc}") from None


def _provenance(path: Path, arrays: dict[str, NDArray]) -> dict[str, Any]:
    """The cloud's ``source`` record (clouds saved before it existed have none)."""
    if "source" not in arrays:
        return {}
    try:
        record = json.loads(str(arrays["source"]))
    except json.JSONDecodeError:
        record = None
    if not isinstance(record, dict):
        raise FileFormatError(f"{path}: the cloud's source record is not a JSON object")
    return record


def load_cloud(path: str | Path) -> SemanticCloud:
    """Read a cloud written by :func:`save_cloud`."""
    arrays = read_npz(path)
    if not is_cloud_file(arrays):
        raise FileFormatError(f"{path}: not a seminspect semantic cloud")
    return cloud_from_arrays(Path(path), arrays)
