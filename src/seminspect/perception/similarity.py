"""Scene similarity for level completion, 000 eq (8).

When the robot comes back within ``d_thresh^I`` of where the current level started, the query
image is matched against the last ``N`` candidate images of the level:

    Γ = Σ_n |M(I_q, i_n)| / |K_q|   if d_curr <= d_thresh^I, else 0

with ``M`` the matched local features and ``K_q`` the query's keypoints. The level is complete
when ``Γ >= Γ_thresh``. The paper matches with LightGlue on a GPU; here OpenCV's ORB features
with a brute-force Hamming matcher, Lowe's ratio test and a RANSAC homography check (which
rejects matches that agree on appearance but not on geometry, e.g. repeated texture) stand in.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import cast

import cv2
import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError

#: Γ_thresh for this matcher, in both presets. 000 Table 1's 0.3 (0.4 for collapsed buildings)
#: is calibrated for LightGlue, which matches across large viewpoint changes. Calibrated by
#: ``bench/similarity_calibration.py`` (city small and collapsed fire station, seeds 0-2; table
#: in ``docs/reproduction.md``): views 3 m or more from a level's first images score at most
#: 0.030 (city) and 0.042 (collapsed), a margin of 1.7x or more; views closing the ring score
#: 0.21-0.95 among collapsed buildings and have medians 0.18-0.25 in the city, 7-23 % of them
#: below 0.07 (each such miss costs one more view).
ORB_GAMMA_THRESHOLD = 0.07


@dataclass(frozen=True, slots=True)
class ImageFeatures:
    """ORB keypoints (pixel coordinates) and binary descriptors of one image."""

    points: NDArray[np.float32]
    descriptors: NDArray[np.uint8] | None

    @property
    def count(self) -> int:
        return len(self.points)


@dataclass
class SceneMatcher:
    """Extracts and matches ORB features for eq (8).

    Args:
        max_features: ORB keypoints per image.
        ratio: Lowe's ratio-test threshold.
        ransac_px: reprojection tolerance of the homography check (pixels).
    """

    max_features: int = 500
    ratio: float = 0.75
    ransac_px: float = 8.0
    _orb: cv2.ORB = field(init=False, repr=False)
    _matcher: cv2.BFMatcher = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if self.max_features < 8 or not 0 < self.ratio < 1 or self.ransac_px <= 0:
            raise InvalidInputError("matcher needs max_features >= 8, 0 < ratio < 1, ransac_px > 0")
        self._orb = cv2.ORB_create(nfeatures=self.max_features)  # type: ignore[attr-defined]
        self._matcher = cv2.BFMatcher(cv2.NORM_HAMMING)

    def features(self, image: NDArray[np.uint8]) -> ImageFeatures:
        """Keypoints and descriptors of a grey (H x W) or colour (H x W x 3) uint8 image."""
        grey = _grey(image)
        keypoints, descriptors = self._orb.detectAndCompute(grey, None)
        points = np.array([k.pt for k in keypoints], dtype=np.float32).reshape(-1, 2)
        return ImageFeatures(points, cast("NDArray[np.uint8] | None", descriptors))

    def matches(self, query: ImageFeatures, candidate: ImageFeatures) -> int:
        """``|M(I_q, i)|``: ratio-test matches that also agree on one homography."""
        if query.descriptors is None or candidate.descriptors is None:
            return 0
        if query.count < 2 or candidate.count < 2:
            return 0
        pairs = self._matcher.knnMatch(query.descriptors, candidate.descriptors, k=2)
        good = [p[0] for p in pairs if len(p) == 2 and p[0].distance < self.ratio * p[1].distance]
        if len(good) < 4:
            return 0
        src = query.points[[m.queryIdx for m in good]]
        dst = candidate.points[[m.trainIdx for m in good]]
        _, inliers = cv2.findHomography(src, dst, cv2.RANSAC, self.ransac_px)
        return 0 if inliers is None else int(inliers.sum())


def scene_similarity(
    matcher: SceneMatcher,
    query: ImageFeatures,
    candidates: Sequence[ImageFeatures],
    distance_to_level_start: float,
    d_thresh: float,
) -> float:
    """Γ of 000 eq (8) for a query against the candidate images of the horizon."""
    if distance_to_level_start > d_thresh or query.count == 0:
        return 0.0
    return sum(matcher.matches(query, c) for c in candidates) / query.count


def _grey(image: NDArray[np.uint8]) -> NDArray[np.uint8]:
    if image.dtype != np.uint8 or image.ndim not in (2, 3):
        raise InvalidInputError("images must be uint8 arrays of shape (H, W) or (H, W, 3)")
    return (
        image
        if image.ndim == 2
        else cast("NDArray[np.uint8]", cv2.cvtColor(image, cv2.COLOR_RGB2GRAY))
    )
