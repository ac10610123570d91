"""From a segmented detection to an observation ``z_k`` (000 Sec III).

The mask's pixels are back-projected with the frame's depth from the pose the robot *believes*
it had (its odometry), as a real robot must: image/odometry desync and drift therefore show up
in the observations, as they did in 000 Sec VII-B.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from seminspect.perception.localisation import Method, erode_mask, localise_points
from seminspect.perception.observation import Observation
from seminspect.sensors import Detection, Frame

#: Masks larger than this are sampled on a regular pixel grid before back-projection.
MAX_MASK_POINTS = 20_000


def detection_points(
    frame: Frame, detection: Detection, erosion_px: int = 0, min_height: float | None = None
) -> np.ndarray:
    """World points (odometry frame) of a detection's mask.

    ``erosion_px`` shrinks the mask first (against masks that bleed onto the background);
    ``min_height`` drops points below that height, i.e. bled pixels on the ground around an
    object that stands on it. A mask larger than ``MAX_MASK_POINTS`` pixels (a building that
    fills the image) is sampled on a regular pixel grid first.
    """
    step = math.ceil(math.sqrt(detection.area_px / MAX_MASK_POINTS))
    pixels = _mask_pixels(detection.mask, erosion_px, max(step, 1))
    points = frame.pixel_points(pixels, use_odometry=True)
    return points if min_height is None else points[points[:, 2] >= min_height]


def _mask_pixels(mask: np.ndarray, erosion_px: int, step: int) -> np.ndarray:
    """Row-major indices of the mask's pixels left after erosion, on every ``step``-th row and
    column of the frame.

    The erosion works in the mask's box grown by one pixel: the zeros around the mask stay
    zeros and keep the crop's edge out of reach, and where the box meets the frame's edge
    the crop's edge is the frame's, as it was for the whole mask.
    """
    height, width = mask.shape
    rows = np.flatnonzero(mask.any(axis=1))
    cols = np.flatnonzero(mask.any(axis=0))
    if not rows.size:
        return rows
    r0, c0 = max(int(rows[0]) - 1, 0), max(int(cols[0]) - 1, 0)
    crop = mask[r0 : min(int(rows[-1]) + 2, height), c0 : min(int(cols[-1]) + 2, width)]
    # The frame's grid rows and columns (multiples of step) within the crop.
    first_row, first_col = -r0 % step, -c0 % step
    kept = erode_mask(crop, erosion_px)[first_row::step, first_col::step]
    return _frame_indices(kept, r0 + first_row, c0 + first_col, step, width)


@numba.njit(cache=True)
def _frame_indices(kept, row0, col0, step, width):
    """Row-major frame indices of the true pixels of ``kept``, whose pixel ``(i, j)`` is the
    frame's ``(row0 + i * step, col0 + j * step)``."""
    found = np.empty(kept.size, np.intp)
    count = 0
    for i in range(kept.shape[0]):
        start = (row0 + i * step) * width + col0
        for j in range(kept.shape[1]):
            if kept[i, j]:
                found[count] = start + j * step
                count += 1
    return found[:count]


def observe(
    frame: Frame,
    detection: Detection,
    *,
    image: str | None = None,
    method: Method = "cluster",
    erosion_px: int = 0,
    min_height: float | None = None,
    max_range: float = math.inf,
) -> Observation | None:
    """The observation of one detection, or None when it cannot be localised within range."""
    position = localise_points(detection_points(frame, detection, erosion_px, min_height), method)
    if position is None:
        return None
    if np.linalg.norm(position - frame.odometry_position) > max_range:
        return None
    return Observation(
        position,
        frame.odometry_orientation,
        label=detection.label,
        score=detection.score,
        mask_area=float(detection.area_px),
        image=image,
        stamp=frame.stamp,
    )
