import math

import cv2
import numpy as np
import pytest

from seminspect.geometry.transforms import quat_from_yaw
from seminspect.perception.detections import MAX_MASK_POINTS, detection_points, observe
from seminspect.sensors import CameraModel, Detection, render
from seminspect.sensors.segmentation import detect
from seminspect.worlds import generate_world


def test_a_detection_is_localised_on_the_car_and_not_on_the_ground() -> None:
    world = generate_world("subterranean", seed=0)
    car = world.instances_of("car")[0]
    frame = render(world, CameraModel(), [1.0, 3.0, 0.7], quat_from_yaw(0.0))
    (detection,) = detect(frame, world, "instance", classes=["car"])
    bled = detection.mask.copy()
    bled[np.roll(detection.mask, 12, axis=0) & ~detection.mask] = True  # bleed onto the floor
    detection.mask = bled
    with_ground = detection_points(frame, detection)
    without = detection_points(frame, detection, min_height=0.15)
    assert with_ground[:, 2].min() < 0.05 <= without[:, 2].min()
    z = observe(frame, detection, min_height=0.15, image="f.jpg")
    assert z is not None and z.label == "car" and z.image == "f.jpg"
    assert car.bbox_min[0] - 0.3 <= z.position[0] <= car.bbox_max[0]  # on the visible end
    assert abs(z.position[1] - 3.0) < 0.5


def test_huge_masks_are_sampled_on_a_pixel_grid() -> None:
    world = generate_world("subterranean", seed=0)
    frame = render(world, CameraModel(), [1.6, 3.0, 0.7], quat_from_yaw(0.0))
    (detection,) = detect(frame, world, "instance", classes=["car"])
    detection.mask[:] = True
    detection.area_px = int(detection.mask.sum())
    points = detection_points(frame, detection)
    assert 0 < len(points) <= MAX_MASK_POINTS


@pytest.fixture(scope="module")
def tunnel_frame():
    world = generate_world("subterranean", seed=0)
    odometry = ([1.1, 3.2, 0.7], quat_from_yaw(0.05))
    return render(world, CameraModel(), [1.0, 3.0, 0.7], quat_from_yaw(0.0), odometry=odometry)


def _whole_frame_points(frame, mask, erosion_px, area_px):
    """Erosion and grid sampling on the whole frame, then its points: the oracle."""
    if erosion_px:
        cross = cv2.getStructuringElement(cv2.MORPH_CROSS, (3, 3))
        mask = cv2.erode(mask.astype(np.uint8), cross, iterations=erosion_px).astype(bool)
    step = math.ceil(math.sqrt(area_px / MAX_MASK_POINTS))
    if step > 1:
        grid = np.zeros_like(mask)
        grid[::step, ::step] = True
        mask = mask & grid
    return frame.points(mask, use_odometry=True)


@pytest.mark.parametrize("seed", range(20))
def test_points_of_masks_eroded_in_their_box_equal_whole_frame_ones(tunnel_frame, seed) -> None:
    rng = np.random.default_rng(seed)
    height, width = tunnel_frame.shape
    blob = np.zeros((height, width), np.uint8)
    for _ in range(int(rng.integers(1, 4))):  # some reach past the frame's edges
        centre = (int(rng.integers(-20, width + 20)), int(rng.integers(-20, height + 20)))
        axes = (int(rng.integers(1, 200)), int(rng.integers(1, 150)))
        cv2.ellipse(blob, centre, axes, float(rng.uniform(0, 180)), 0, 360, 1, -1)
    mask = (blob > 0) & (rng.random((height, width)) > 0.02)
    area_px = int(rng.choice([mask.sum(), 4 * MAX_MASK_POINTS, 10 * MAX_MASK_POINTS]))
    detection = Detection("car", mask, area_px, 1.0, (0, 0, width, height), 1, "instance", 5.0)
    for erosion_px in (0, 1, 3):
        np.testing.assert_array_equal(
            detection_points(tunnel_frame, detection, erosion_px),
            _whole_frame_points(tunnel_frame, mask, erosion_px, detection.area_px),
        )
