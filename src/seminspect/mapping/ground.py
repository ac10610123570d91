"""Ground, objects and labels for bare point clouds (no labels, no embeddings).

The geometric path of 001's phase 1 for users' unlabelled LiDAR: a progressive morphological
filter (Zhang et al. 2003, IEEE TGRS 41(4)) separates ground from non-ground, the non-ground
points are clustered by DBSCAN (``geometry.clustering``) into objects, and every point gets a
label the terrain pipeline takes: ``ground``, ``object``, or ``outlier`` (non-ground points in
no cluster, which carry no semantics and are skipped like SemanticKITTI's outliers).

The grid cell and the DBSCAN radius derive from the cloud's median nearest-neighbour spacing,
so the same parameters serve a mobile scan at centimetres and an airborne survey at metres.
The remaining parameters describe the scene, not the sensor: the largest object to remove
(Zhang's maximum window), the steepest terrain slope, and the height a surface must rise to
count as an object. Their defaults were chosen on the 15 ISPRS filter-test samples (the
table of ``docs/terrain.md``, ``bench/ground_filter.py``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.clustering import dbscan_labels
from seminspect.geometry.nearest import median_spacing

GROUND, OBJECT, OUTLIER = 0, 1, 2
BARE_LABEL_NAMES: dict[int, str] = {GROUND: "ground", OBJECT: "object", OUTLIER: "outlier"}
#: Grids larger than this many cells get coarser cells (memory and time stay bounded).
_MAX_GRID_CELLS = 16_000_000


@dataclass(frozen=True)
class GroundFilterParams:
    """Parameters of the progressive morphological filter and of the object clustering.

    Lengths are metres. ``cells_per_spacing`` and ``eps_per_spacing`` scale the median
    spacing; the others are properties of the scene.
    """

    cells_per_spacing: float = 1.0  # Zhang's cell size c, in spacings
    max_window: float = 30.0  # the largest object removed [m] (Zhang's maximum window)
    slope: float = 0.3  # steepest terrain slope s (rise over run), Zhang eq (5)
    initial_height: float = 0.5  # dh_0 [m], Zhang eq (5), at most ...
    initial_height_per_spacing: float = 3.0  # ... this many spacings (dense mobile scans)
    max_height: float = 2.5  # dh_max [m], Zhang eq (5)
    eps_per_spacing: float = 6.0  # DBSCAN radius of object points, in spacings
    min_object_points: int = 5  # DBSCAN min_samples: an airborne tree has a few returns

    def __post_init__(self) -> None:
        for name in ("cells_per_spacing", "max_window", "initial_height", "eps_per_spacing",
                     "initial_height_per_spacing"):  # fmt: skip
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise InvalidInputError(f"ground filter {name} must be > 0, got {value}")
        if not (math.isfinite(self.slope) and self.slope >= 0):
            raise InvalidInputError(f"ground filter slope must be >= 0, got {self.slope}")
        if not self.max_height >= self.initial_height:
            raise InvalidInputError("ground filter max_height must be at least initial_height")
        if self.min_object_points < 1:
            raise InvalidInputError("ground filter min_object_points must be at least 1")


@dataclass
class BareCloudLabels:
    """Labels of a bare cloud and what the filter saw on the way."""

    labels: NDArray[np.int64]  # GROUND, OBJECT or OUTLIER per point
    objects: NDArray[np.int64]  # cluster id per point, -1 for ground and outliers
    spacing: float  # median nearest-neighbour spacing [m]
    cell: float  # grid cell of the filter [m]
    eps: float  # DBSCAN radius of the object clustering [m]
    seconds: dict[str, float] = field(default_factory=dict)

    @property
    def is_ground(self) -> NDArray[np.bool_]:
        return self.labels == GROUND

    @property
    def names(self) -> dict[int, str]:
        return dict(BARE_LABEL_NAMES)

    def object_sizes(self, points: NDArray[np.float64]) -> list[tuple[int, NDArray[np.float64]]]:
        """Points and axis-aligned box size of every object, largest first."""
        found = []
        for cluster in np.unique(self.objects[self.objects >= 0]):
            member = points[self.objects == cluster]
            found.append((len(member), member.max(axis=0) - member.min(axis=0)))
        return sorted(found, key=lambda item: -item[0])


def cloud_spacing(points: NDArray[np.float64], seed: int = 0) -> float:
    """The median 3D spacing of a bare cloud, refused in one line where none exists."""
    if len(points) < 2:
        raise InvalidInputError("a bare cloud needs at least two points")
    spacing = median_spacing(points, seed=seed)
    if not math.isfinite(spacing):
        raise InvalidInputError("every point of the bare cloud lies on top of another")
    return spacing


def _grid(points: NDArray[np.float64], cell: float) -> tuple[NDArray[np.int64], tuple[int, int]]:
    """Flat grid index of every point and the grid's shape."""
    ij = np.floor((points[:, :2] - points[:, :2].min(axis=0)) / cell).astype(np.int64)
    shape = (int(ij[:, 0].max()) + 1, int(ij[:, 1].max()) + 1)
    return ij[:, 0] * shape[1] + ij[:, 1], shape


def _filled(values: NDArray[np.float64], shape: tuple[int, int]) -> NDArray[np.float64]:
    """A grid with every empty (non-finite) cell taking its nearest filled cell's value."""
    grid = values.reshape(shape)
    empty = ~np.isfinite(grid)
    if empty.any():
        _, nearest = ndimage.distance_transform_edt(empty, return_indices=True)
        grid = grid[tuple(nearest)]
    return grid


def filter_cell(spacing: float, extent: NDArray[np.float64], params: GroundFilterParams) -> float:
    """The grid cell: ``cells_per_spacing`` spacings, coarser when the grid would be huge."""
    cell = params.cells_per_spacing * spacing
    cells = float(np.prod(extent[:2] / cell + 1))
    if cells > _MAX_GRID_CELLS:
        cell *= math.sqrt(cells / _MAX_GRID_CELLS)
    return cell


def windows(cell: float, params: GroundFilterParams) -> list[int]:
    """Zhang's exponentially growing windows ``w_k = 2 b^k + 1`` cells (b = 2), eq (4), up to
    the maximum window."""
    sizes, k = [], 0
    while (2 * 2**k + 1) * cell <= params.max_window:
        sizes.append(2 * 2**k + 1)
        k += 1
    return sizes or [3]


def initial_height(spacing: float, params: GroundFilterParams) -> float:
    """``dh_0``: the scene's height threshold, lowered on dense scans, where ground noise is
    a few centimetres and the lower half of a parked car would pass 0.5 m."""
    return min(params.initial_height, params.initial_height_per_spacing * spacing)


def progressive_morphological_filter(
    points: NDArray[np.float64], cell: float, params: GroundFilterParams, first_height: float
) -> NDArray[np.bool_]:
    """Whether each point is ground (Zhang et al. 2003, Sec II).

    The minimum surface on the grid is opened with windows of growing size; a point rising
    more than the height threshold above an opened surface is non-ground. The threshold grows
    with the window as terrain of slope ``s`` would (eq 5): ``dh_k = s (w_k - w_{k-1}) c +
    dh_0``, at most ``dh_max``, and ``dh_0`` (``first_height``) for the first window.
    """
    flat, shape = _grid(points, cell)
    lowest = np.full(shape[0] * shape[1], np.inf)
    np.minimum.at(lowest, flat, points[:, 2])
    surface = _filled(lowest, shape)
    ground = np.ones(len(points), dtype=bool)
    previous = 1
    for size in windows(cell, params):
        surface = ndimage.grey_opening(surface, size=(size, size))
        threshold = first_height
        if size > 3:
            threshold = min(params.slope * (size - previous) * cell + threshold, params.max_height)
        ground &= points[:, 2] - surface.ravel()[flat] <= threshold
        previous = size
    return ground


def height_above_ground(
    points: NDArray[np.float64], ground: NDArray[np.bool_], cell: float
) -> NDArray[np.float64]:
    """Height of every point above the mean ground height of its cell (nearest cell with
    ground where its own has none)."""
    flat, shape = _grid(points, cell)
    cells = shape[0] * shape[1]
    sums = np.bincount(flat[ground], weights=points[ground, 2], minlength=cells)
    counts = np.bincount(flat[ground], minlength=cells)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(counts > 0, sums / np.maximum(counts, 1), np.inf)
    return points[:, 2] - _filled(mean, shape).ravel()[flat]


def label_bare_cloud(
    points: NDArray[np.float64], params: GroundFilterParams | None = None, seed: int = 0
) -> BareCloudLabels:
    """Ground, object and outlier labels of a cloud in metres (see the module docstring)."""
    params = params or GroundFilterParams()
    cloud = np.asarray(points, dtype=np.float64)
    seconds: dict[str, float] = {}
    start = time.perf_counter()
    spacing = cloud_spacing(cloud, seed)
    cell = filter_cell(spacing, np.ptp(cloud, axis=0), params)
    seconds["spacing"] = time.perf_counter() - start
    start = time.perf_counter()
    ground = progressive_morphological_filter(cloud, cell, params, initial_height(spacing, params))
    seconds["ground"] = time.perf_counter() - start
    start = time.perf_counter()
    objects = np.full(len(cloud), -1, dtype=np.int64)
    above = np.flatnonzero(~ground)
    eps = params.eps_per_spacing * spacing
    if above.size:
        objects[above] = dbscan_labels(cloud[above], eps, params.min_object_points)
    seconds["objects"] = time.perf_counter() - start
    labels = np.where(ground, GROUND, np.where(objects >= 0, OBJECT, OUTLIER)).astype(np.int64)
    return BareCloudLabels(labels, objects, spacing, cell, eps, seconds)


def filter_errors(predicted_ground: NDArray[np.bool_], true_ground: NDArray[np.bool_]) -> dict:
    """Type I, type II and total error (Sithole & Vosselman 2004, Sec 4.1), as fractions.

    Type I: ground points rejected as objects, over the ground points; type II: object points
    accepted as ground, over the object points; total: misclassified points over all.
    """
    predicted = np.asarray(predicted_ground, dtype=bool)
    truth = np.asarray(true_ground, dtype=bool)
    if predicted.shape != truth.shape:
        raise InvalidInputError(f"{predicted.shape[0]} predictions for {truth.shape[0]} points")
    ground, objects = int(truth.sum()), int((~truth).sum())
    return {
        "type_1": float(np.sum(truth & ~predicted) / max(ground, 1)),
        "type_2": float(np.sum(~truth & predicted) / max(objects, 1)),
        "total": float(np.sum(predicted != truth) / max(truth.size, 1)),
    }
