import dataclasses
import math

import cv2
import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.core.rng import make_rng
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.sensors import CameraModel, detect, detect_instances, detect_parts, render
from seminspect.sensors.noise import NoiseModel, make_noise
from seminspect.sensors.segmentation import key_boxes
from seminspect.worlds import WorldBuilder
from seminspect.worlds.shapes import pose_matrix
from seminspect.worlds.vehicles import vehicle_pieces

CAMERA = CameraModel(width=320, height=240)


@pytest.fixture(scope="module")
def scene():
    """A car 6 m ahead, a truck 25 m ahead to the left, seen from the origin looking along +x."""
    builder = WorldBuilder("street")
    builder.add_ground((-10, -30), (60, 30))
    builder.add_object(vehicle_pieces("car"), "car", pose_matrix((8.0, -1.0, 0.0), 0.3))
    builder.add_object(vehicle_pieces("truck"), "truck", pose_matrix((28.0, 9.0, 0.0), 1.2))
    world = builder.build([(-10, -30, 0), (60, 30, 5)], (0, 0, 0))
    frame = render(world, CAMERA, (0.0, 0.0, 0.7), quat_from_yaw(0.0))
    return world, frame


def test_ideal_detections_are_the_ground_truth_masks(scene) -> None:
    world, frame = scene
    found = {d.label: d for d in detect_instances(frame, world, ["car", "truck"])}
    assert set(found) == {"car", "truck"}
    car = found["car"]
    np.testing.assert_array_equal(car.mask, frame.instance == car.instance_id)
    assert car.area_px == car.mask.sum() and car.score == 1.0 and not car.is_false_positive
    x0, y0, x1, y1 = car.bbox
    assert car.mask[y0:y1, x0:x1].sum() == car.area_px
    assert car.mask[:, x0].any() and car.mask[y1 - 1].any() and not car.mask[:, x1:].any()
    assert 5.0 < car.depth_m < 9.0 and 20.0 < found["truck"].depth_m < 30.0
    assert [d.label for d in detect_instances(frame, world, ["truck", "bus"])] == ["truck"]


def test_part_detections(scene) -> None:
    world, frame = scene
    parts = detect_parts(frame, world, classes=["car"])
    labels = {d.label for d in parts}
    assert {"back-bumper", "back-glass", "back-left-door", "back-left-light"} <= labels
    assert all(world.instances[d.instance_id].class_name == "car" for d in parts)
    for d in parts:
        pixels = (frame.instance == d.instance_id) & (frame.part_id == world.part_id(d.label))
        np.testing.assert_array_equal(d.mask, pixels)
    only = detect_parts(frame, world, classes=["car"], parts=["back-glass", "hood"])
    assert [d.label for d in only] == ["back-glass"]


def _areas(detections):
    return {d.label: d.area_px for d in detections}


def test_erosion_shrinks_and_bleeding_grows_onto_background(scene) -> None:
    world, frame = scene
    ideal = _areas(detect_instances(frame, world))
    eroded = detect_instances(frame, world, None, make_noise({"mask_erosion_px": 2}), make_rng(0))
    assert all(d.area_px < ideal[d.label] for d in eroded)
    bled = detect_instances(frame, world, None, make_noise({"mask_bleed_px": 3}), make_rng(0))
    for d in bled:
        assert d.area_px > ideal[d.label]
        extra = d.mask & (frame.instance != d.instance_id)
        assert extra.any() and (frame.instance[extra] == 0).all()  # only background is taken


def test_missed_detections_follow_range_and_area(scene) -> None:
    world, frame = scene
    rng = make_rng(1, "miss")
    never = make_noise({"miss_probability": 1.0})
    assert detect_instances(frame, world, None, never, rng) == []
    by_range = make_noise({"miss_per_metre": 0.03})
    counts = {"car": 0, "truck": 0}
    for _ in range(200):
        for d in detect_instances(frame, world, None, by_range, rng):
            counts[d.label] += 1
    assert counts["car"] > counts["truck"] + 40  # ~82 % vs ~24 % seen
    tiny = make_noise({"miss_area_scale_px": 1e9})
    assert detect_instances(frame, world, None, tiny, rng) == []
    assert by_range.miss_chance(10.0, 500) == pytest.approx(0.3)
    assert tiny.miss_chance(0.0, 10.0) == pytest.approx(1.0, abs=1e-6)


def test_minimum_area_drops_small_masks(scene) -> None:
    world, frame = scene
    ideal = _areas(detect_instances(frame, world))
    limit = (ideal["car"] + ideal["truck"]) // 2
    kept = detect_instances(
        frame, world, None, make_noise({"min_mask_area_px": limit}), make_rng(0)
    )
    assert [d.label for d in kept] == ["car" if ideal["car"] > ideal["truck"] else "truck"]


def test_confidence_noise_and_false_positives(scene) -> None:
    world, frame = scene
    noisy = make_noise({"score_mean": 0.8, "score_sigma": 0.05})
    rng = make_rng(2, "scores")
    scores = [d.score for _ in range(100) for d in detect_instances(frame, world, None, noisy, rng)]
    assert abs(np.mean(scores) - 0.8) < 0.02 and 0.03 < np.std(scores) < 0.07
    spurious = make_noise({"false_positives_per_frame": 3.0})
    fakes = [
        d
        for _ in range(60)
        for d in detect_instances(frame, world, ["car", "truck"], spurious, rng)
        if d.is_false_positive
    ]
    assert 120 < len(fakes) < 240
    assert {d.label for d in fakes} == {"car", "truck"}
    assert all(d.instance_id == -1 and d.area_px == d.mask.sum() > 0 for d in fakes)
    part_fakes = detect_parts(frame, world, spurious, rng, parts=["hood"])
    assert all(d.label == "hood" for d in part_fakes)


def test_noisy_detection_is_seeded(scene) -> None:
    world, frame = scene
    noise = make_noise({"false_positives_per_frame": 2.0, "score_sigma": 0.1}, base="realistic")
    a = detect_instances(frame, world, None, noise, make_rng(7))
    b = detect_instances(frame, world, None, noise, make_rng(7))
    assert [(d.label, d.score, d.bbox) for d in a] == [(d.label, d.score, d.bbox) for d in b]
    with pytest.raises(InvalidInputError, match="random generator"):
        detect_instances(frame, world, None, noise)
    with pytest.raises(InvalidInputError, match="level"):
        detect(frame, world, "scene")
    assert math.isinf(detect(frame, world, "instance")[0].depth_m) is False


def test_key_boxes_match_numpy_unique_and_each_values_extent() -> None:
    rng = np.random.default_rng(5)
    small = rng.integers(-3, 40, (48, 64))
    large = np.append(rng.integers(0, 5, 19), 10**9).reshape(4, 5)  # beyond a table: sorted
    instances = rng.integers(0, 6, (30, 20)).astype(np.int32)  # a frame's own dtype
    for key in (small, large, instances, np.zeros((4, 4), dtype=np.int64)):
        values, boxes = key_boxes(key)
        np.testing.assert_array_equal(values, np.unique(key[key > 0]))
        for value, box in zip(values, boxes, strict=True):
            rows, cols = np.nonzero(key == value)
            assert box.tolist() == [rows.min(), cols.min(), rows.max() + 1, cols.max() + 1]


def _random_labels(scene, seed: int):
    """The scene's frame with random blobs of its car and truck, and of parts, some touching
    the frame's edges, and random depths with holes."""
    world, frame = scene
    rng = np.random.default_rng(seed)
    height, width = frame.shape
    instance = np.zeros((height, width), np.int32)
    part = np.zeros((height, width), np.int16)
    for _ in range(int(rng.integers(3, 12))):
        inst = int(rng.choice(list(world.instances)))
        centre = (int(rng.integers(-10, width + 10)), int(rng.integers(-10, height + 10)))
        axes = (int(rng.integers(1, 40)), int(rng.integers(1, 40)))
        blob = np.zeros((height, width), np.uint8)
        cv2.ellipse(blob, centre, axes, float(rng.uniform(0, 180)), 0, 360, 1, -1)
        instance[blob > 0] = inst
        part[blob > 0] = int(rng.integers(0, len(world.part_names)))
    instance[rng.random((height, width)) < 0.01] = 0  # specks of background inside masks
    part[instance == 0] = 0
    depth = rng.uniform(1, 30, (height, width)).astype(np.float32)
    depth[rng.random((height, width)) < 0.05] = np.inf
    return dataclasses.replace(frame, instance=instance, part_id=part, depth=depth)


def _whole_frame_masks(frame, world, level, noise):
    """(mask, median depth) of every candidate, each step on whole-frame masks: the oracle."""
    key = frame.instance.astype(np.int64)
    if level == "part":
        key = key * len(world.part_names) + frame.part_id
        key[frame.part_id == 0] = 0
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (3, 3))
    result = []
    for value in np.unique(key[key > 0]):
        shaped = (key == value).astype(np.uint8)
        if noise.mask_erosion_px:
            shaped = cv2.erode(shaped, kernel, iterations=noise.mask_erosion_px)
        mask = shaped.astype(bool)
        if noise.mask_bleed_px:
            grown = cv2.dilate(shaped, kernel, iterations=noise.mask_bleed_px).astype(bool)
            mask |= grown & (frame.instance == 0)
        if mask.sum() >= noise.min_mask_area_px:
            depths = frame.depth[mask]
            depths = depths[np.isfinite(depths)]
            result.append((mask, float(np.median(depths)) if len(depths) else math.inf))
    return result


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("level", ["instance", "part"])
@pytest.mark.parametrize(("erosion", "bleed"), [(0, 0), (2, 2), (1, 4), (3, 0), (0, 3)])
def test_masks_cut_from_their_boxes_equal_whole_frame_masks(scene, seed, level, erosion, bleed):
    world, _ = scene
    frame = _random_labels(scene, seed)
    noise = NoiseModel(mask_erosion_px=erosion, mask_bleed_px=bleed, min_mask_area_px=2)
    found = detect(frame, world, level, noise=noise, rng=make_rng(seed, "test"))
    expected = _whole_frame_masks(frame, world, level, noise)
    assert len(found) == len(expected)
    for detection, (mask, depth) in zip(found, expected, strict=True):
        np.testing.assert_array_equal(detection.mask, mask)
        assert detection.area_px == mask.sum()
        assert detection.depth_m == depth
        rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
        assert detection.bbox == (cols[0], rows[0], cols[-1] + 1, rows[-1] + 1)
