"""Eq (8) on images with real texture: a revisit scores high, another scene low."""

import cv2
import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.perception.similarity import SceneMatcher, scene_similarity


def texture(seed: int, size: int = 900) -> np.ndarray:
    """A blotchy grey texture with corners for ORB to find."""
    rng = np.random.default_rng(seed)
    small = rng.integers(0, 256, (size // 12, size // 12)).astype(np.uint8)
    image = cv2.resize(small, (size, size), interpolation=cv2.INTER_NEAREST)
    return cv2.GaussianBlur(image, (3, 3), 0)


@pytest.fixture(scope="module")
def scene() -> dict[str, np.ndarray]:
    base, other = texture(1), texture(2)
    return {
        "query": base[100:580, 100:740],
        "revisit": base[130:610, 140:780],  # the same surface, shifted by 30 x 40 px
        "other": other[100:580, 100:740],
    }


def test_a_revisit_matches_and_another_scene_does_not(scene) -> None:
    matcher = SceneMatcher()
    query = matcher.features(scene["query"])
    revisit = matcher.features(scene["revisit"])
    other = matcher.features(scene["other"])
    assert query.count > 300
    same = scene_similarity(matcher, query, [revisit], 1.0, d_thresh=5.0)
    different = scene_similarity(matcher, query, [other], 1.0, d_thresh=5.0)
    assert same > 0.3 > different  # Γ_thresh = 0.3, 000 Table 1
    assert different < 0.05


def test_gamma_sums_over_the_horizon_and_is_zero_far_from_the_level_start(scene) -> None:
    matcher = SceneMatcher()
    query, revisit = matcher.features(scene["query"]), matcher.features(scene["revisit"])
    one = scene_similarity(matcher, query, [revisit], 1.0, 5.0)
    two = scene_similarity(matcher, query, [revisit, revisit], 1.0, 5.0)
    assert two == pytest.approx(2 * one)
    assert scene_similarity(matcher, query, [revisit], 5.01, 5.0) == 0.0


def test_blank_images_and_bad_arguments() -> None:
    matcher = SceneMatcher()
    blank = matcher.features(np.zeros((480, 640), np.uint8))
    assert blank.count == 0 and scene_similarity(matcher, blank, [blank], 0.0, 5.0) == 0.0
    with pytest.raises(InvalidInputError):
        matcher.features(np.zeros((4, 4), np.float32))
    with pytest.raises(InvalidInputError):
        SceneMatcher(ratio=1.5)
