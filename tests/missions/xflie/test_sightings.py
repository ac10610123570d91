from fake_platform import FakePlatform, car_in_view, fake_context
from seminspect.missions.xflie.sightings import register_targets, target_view


def test_a_detected_car_is_registered_where_its_pixels_lie() -> None:
    platform = FakePlatform(position=(0.0, 0.0, 0.7))
    car_in_view(platform)
    ctx, events = fake_context(platform)
    register_targets(ctx, ctx.capture())
    (car,) = ctx.graph.targets()
    assert car.label == "car" and 3.5 < car.position[0] < 4.5 and abs(car.position[1]) < 1.0
    assert events.kinds() == ["detected"]


def test_the_target_view_gates_detections_by_distance_to_the_target() -> None:
    platform = FakePlatform(position=(0.0, 0.0, 0.7))
    car_in_view(platform)
    ctx, _ = fake_context(platform)
    frame = ctx.capture()
    register_targets(ctx, frame)
    (car,) = ctx.graph.targets()
    mask, points = target_view(ctx, frame, car)
    assert mask is not None and len(points) > 0
    assert target_view(ctx, frame, car, gate=-1.0)[0] is None


def test_detections_below_the_confidence_threshold_are_ignored() -> None:
    platform = FakePlatform()
    car_in_view(platform)
    ctx, _ = fake_context(platform, settings={"min_score": 0.95})
    register_targets(ctx, ctx.capture())
    assert not ctx.graph.targets()
