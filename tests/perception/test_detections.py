import numpy as np

from seminspect.geometry.transforms import quat_from_yaw
from seminspect.perception.detections import MAX_MASK_POINTS, detection_points, observe
from seminspect.sensors import CameraModel, render
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
