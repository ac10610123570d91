"""What a routine inspection is judged by (002 Sec IV-V), measured against the current world.

* **Viewing distance**: distance along the optical axis to the surface at the image centre
  (median depth of the central 5 x 5 pixels), against ``d_view``.
* **ROI coverage**: the share of a region observed at the required resolution. The region's
  outline is sampled every 10 cm and each sample is carried along the region's normal onto the
  *current* surface (by ray casting); a sample counts once some view saw that surface point
  unoccluded from a range within ``d_view ± 0.3 m`` (the viewing-distance tolerance of the
  acceptance figures): our reading of "at the required resolution", which photogrammetry wants
  consistent, so too close counts as missed as well as too far.
* **Change report** between ``M_H`` and ``M_C`` per region: cells within the region's outline
  and 2 m of its plane, known in both maps, that turned occupied (added) or free (removed).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from seminspect.mapping.voxel import FREE, OCCUPIED, VoxelMap
from seminspect.planning.global_views import InspectionRegion
from seminspect.sensors import Frame
from seminspect.worlds import World

SAMPLE_SPACING_M = 0.1
RANGE_TOLERANCE_M = 0.3
#: A sample is seen when the frame's depth at its pixel is within this of its own depth.
OCCLUSION_TOLERANCE_M = 0.05
CHANGE_SLAB_M = 2.0


def view_distance(frame: Frame) -> float:
    """Median depth of the 5 x 5 pixels at the image centre (NaN if none saw a surface)."""
    height, width = frame.shape
    patch = frame.depth[height // 2 - 2 : height // 2 + 3, width // 2 - 2 : width // 2 + 3]
    finite = patch[np.isfinite(patch)]
    return float(np.median(finite)) if len(finite) else float("nan")


def region_samples(
    region: InspectionRegion, world: World, outward: NDArray[np.float64], reach: float = 3.0
) -> NDArray[np.float64]:
    """Points of the current surface behind the region's outline, every 10 cm (``(K, 3)``)."""
    u, v, _ = region.frame()
    outline = region.plane_coordinates(region.vertices)
    lo, hi = outline.min(axis=0), outline.max(axis=0)
    grid = np.stack(
        np.meshgrid(
            np.arange(lo[0], hi[0] + 1e-9, SAMPLE_SPACING_M),
            np.arange(lo[1], hi[1] + 1e-9, SAMPLE_SPACING_M),
            indexing="ij",
        ),
        axis=-1,
    ).reshape(-1, 2)
    plane = region.centroid + grid[:, :1] * u + grid[:, 1:] * v
    plane = plane[region.contains(plane, slab=0.01)]
    starts = plane + outward * reach
    directions = np.broadcast_to(-outward, starts.shape).astype(np.float32)
    distance, face = world.raycaster.cast(starts, directions, np.full(len(starts), 2 * reach))
    hit = face >= 0
    return starts[hit] - outward * distance[hit, None]


def seen_samples(
    frame: Frame, samples: NDArray[np.float64], min_range: float, max_range: float
) -> NDArray[np.bool_]:
    """Which samples the frame saw unoccluded from ``min_range``-``max_range`` along its axis."""
    rotation = Rotation.from_quat(frame.orientation).as_matrix()
    body = (samples - frame.position) @ rotation  # body frame: x forward, y left, z up
    depth = body[:, 0]
    camera = frame.camera
    with np.errstate(divide="ignore", invalid="ignore"):
        col = np.rint(camera.cx - camera.fx * body[:, 1] / depth).astype(np.int64)
        row = np.rint(camera.cy - camera.fx * body[:, 2] / depth).astype(np.int64)
    height, width = frame.shape
    inside = (depth >= max(min_range, 1e-6)) & (depth <= max_range) & (col >= 0) & (col < width)
    inside &= (row >= 0) & (row < height)
    seen = np.zeros(len(samples), dtype=bool)
    index = np.flatnonzero(inside)
    measured = frame.depth[row[index], col[index]]
    seen[index] = np.abs(measured - depth[index]) <= OCCLUSION_TOLERANCE_M
    return seen


@dataclass(frozen=True)
class RegionChange:
    """Occupied volume that appeared or vanished near one region between ``M_H`` and ``M_C``."""

    region: str
    added_m3: float
    removed_m3: float
    compared_m3: float


def region_change(region: InspectionRegion, prior: VoxelMap, current: VoxelMap) -> RegionChange:
    """Cell-by-cell change near ``region``; the two maps must share one grid."""
    centres = prior.index_to_world(np.argwhere(np.ones(prior.shape, dtype=bool)))
    near = region.contains(centres, slab=CHANGE_SLAB_M)
    before = prior.states.reshape(-1)[near]
    after = current.states.reshape(-1)[near]
    known = (before != 0) & (after != 0)
    volume = prior.resolution**3
    return RegionChange(
        region.name,
        float(((before == FREE) & (after == OCCUPIED) & known).sum() * volume),
        float(((before == OCCUPIED) & (after == FREE) & known).sum() * volume),
        float(known.sum() * volume),
    )


def change_masks(prior: VoxelMap, current: VoxelMap) -> tuple[NDArray, NDArray]:
    """Boolean grids of cells that turned occupied (added) and free (removed)."""
    added = (prior.states == FREE) & (current.states == OCCUPIED)
    removed = (prior.states == OCCUPIED) & (current.states == FREE)
    return added, removed
