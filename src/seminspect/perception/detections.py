"""From a segmented detection to an observation ``z_k`` (000 Sec III).

The mask's pixels are back-projected with the frame's depth from the pose the robot *believes*
it had (its odometry), as a real robot must: image/odometry desync and drift therefore show up
in the observations, as they did in 000 Sec VII-B.
"""

from __future__ import annotations

import math

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
    mask = erode_mask(detection.mask, erosion_px)
    step = math.ceil(math.sqrt(detection.area_px / MAX_MASK_POINTS))
    if step > 1:
        grid = np.zeros_like(mask)
        grid[::step, ::step] = True
        mask = mask & grid
    points = frame.points(mask, use_odometry=True)
    return points if min_height is None else points[points[:, 2] >= min_height]


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
