"""Phase 1 from the simulator (001 Sec III-A) and its quality on the small outdoor world."""

import math

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.graphs.terrain.prompting import TaskPrompts
from seminspect.graphs.terrain.scene_graph import build_terrain_graph
from seminspect.mapping.semantic_cloud import SemanticCloud, transform_points
from seminspect.missions.terrain.mapping import (
    MappingParams,
    SensorRig,
    drive_samples,
    evaluate_on_world,
    frame_segments,
    make_mapping_params,
    map_world,
    rig_poses,
    source_world,
)
from seminspect.perception.encoders import Calibration
from seminspect.sensors import render
from seminspect.worlds import generate_world

PROMPTS = TaskPrompts.parse("sidewalk,grass,asphalt", "image of a tree,image of a car")
#: The hashing test encoder's captions of four words score 0.39-0.5 against their own name.
CALIBRATION = Calibration(terrain=0.3, objects=0.45, null_task=0.25)


@pytest.fixture(scope="module")
def world():
    return generate_world("outdoor", "small", seed=0)


@pytest.fixture(scope="module")
def mapped(world, fake_encoder):
    from dataclasses import replace

    encoder = replace(fake_encoder, noise=0.3, seed=0)
    progress = []
    run = map_world(
        world,
        encoder,
        params=MappingParams(spacing=3.0),
        on_frame=lambda done, total: progress.append((done, total)),
    )
    return run, progress


def test_drive_samples_follow_the_path_at_the_spacing() -> None:
    path = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 0.0], [10.0, 5.0]])
    points, yaws = drive_samples(path, 3.0)
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    assert np.all(steps <= 3.0 + 1e-9) and steps.sum() == pytest.approx(15.0)
    for waypoint in path:
        assert np.min(np.linalg.norm(points - waypoint, axis=1)) < 1e-9
    np.testing.assert_allclose(yaws[: 1 + 4], 0.0)  # start and the four steps of the first leg
    np.testing.assert_allclose(yaws[5:], math.pi / 2)
    with pytest.raises(PlanningError, match="no length"):
        drive_samples(np.array([[1.0, 1.0], [1.0, 1.0]]), 1.0)


def test_rig_calibration_projects_the_heading_to_the_image_centre() -> None:
    rig = SensorRig()
    camera_position = np.array([4.0, 2.0, 0.8])
    yaw = 0.7
    T_world_lidar, T_world_camera = rig_poses(rig, camera_position, yaw)
    ahead = camera_position + 10.0 * np.array([math.cos(yaw), math.sin(yaw), 0.0])
    optical = transform_points(np.linalg.inv(T_world_camera), ahead[None])[0]
    np.testing.assert_allclose(optical, [0.0, 0.0, 10.0], atol=1e-9)  # straight ahead = +z
    lidar_in_camera = np.linalg.inv(T_world_camera) @ T_world_lidar
    np.testing.assert_allclose(lidar_in_camera[:3, 3], [0.0, -0.25, -0.1], atol=1e-9)


def test_frame_segments_are_objects_and_ground_classes(world) -> None:
    car = world.instances_of("car")[0]
    eye = car.centroid + np.array([-8.0, 0.0, 0.0])
    eye[2] = 0.8
    frame = render(world, SensorRig().camera.scaled(4), eye, quat_from_yaw(0.0))
    ids, segments = frame_segments(frame, world)
    assert ids.shape == frame.shape and ids.max() == len(segments) - 1
    assert np.all(ids[~np.isfinite(frame.depth)] == -1)  # the sky is no segment
    for k, segment in enumerate(segments):
        mask = ids == k
        classes = {world.class_names[c] for c in np.unique(frame.class_id[mask])}
        assert classes == {segment.label}
        assert len(np.unique(frame.instance[mask])) == 1  # one object or one ground class
        assert segment.image.ndim == 3 and segment.image.shape[2] == 3
    labels = [s.label for s in segments]
    assert "car" in labels and {"sidewalk", "asphalt"} <= set(labels)


@pytest.mark.slow
def test_mapping_fuses_many_views_per_point_and_records_its_source(world, mapped) -> None:
    run, progress = mapped
    assert progress[-1] == (run.frames, run.frames) and len(progress) == run.frames
    assert run.distance == pytest.approx(80.0)
    cloud = run.cloud
    assert len(cloud) > 10_000 and cloud.counts.sum() == run.fused  # one count per fused point
    assert np.mean(cloud.counts >= 2) > 0.3 and cloud.counts.max() >= 10  # multi-view averages
    assert np.all(cloud.points[:, 2] > -0.05) and np.all(cloud.points[:, 2] < 8.0)
    assert cloud.source["world"] == {
        "name": "outdoor",
        "scenario": "small",
        "seed": 0,
        "options": {},
    }
    assert cloud.source["frames"] == run.frames and cloud.source["spacing"] == 3.0
    again = source_world(cloud)
    np.testing.assert_array_equal(again.mesh.vertices, world.mesh.vertices)
    assert set(run.seconds) == {"sensors", "segments", "fusion", "total"}


@pytest.mark.slow
def test_quality_on_the_small_world_meets_the_targets(world, mapped, fake_encoder) -> None:
    run, _ = mapped
    build = build_terrain_graph(run.cloud, PROMPTS, fake_encoder, calibration=CALIBRATION)
    quality = evaluate_on_world(build, world, fake_encoder)
    cars, trees = quality.objects["image of a car"], quality.objects["image of a tree"]
    assert cars.match.truth == "car" and cars.scores is not None and trees.scores is not None
    assert cars.scores.ground_truth == 2 and cars.scores.mean_iou > 0.5
    assert cars.scores.precision >= 0.9 and cars.scores.recall >= 0.9
    assert trees.scores.ground_truth == 2
    assert trees.scores.precision >= 0.9 and trees.scores.recall >= 0.9
    for terrain in PROMPTS.terrain:
        places = quality.places[terrain]
        assert places.match.truth == terrain and places.scores.patches >= 1
        assert places.points_on_terrain is not None and places.points_on_terrain > 0.97
        assert places.scores.all_connected and places.scores.off_terrain == 0, places
    record = quality.to_json()  # the summary.json record: flat per prompt
    assert record["objects"]["image of a car"] == {
        **cars.match.to_json(),
        **cars.scores.to_json(),
    }
    assert list(record["places"]["sidewalk"])[3:5] == ["points_on_terrain", "terrain"]


@pytest.mark.slow
def test_mapping_is_deterministic(fake_encoder) -> None:
    from dataclasses import replace

    world = generate_world("outdoor", "small", seed=3)
    world.metadata["drive_path"] = world.metadata["drive_path"][:2]
    params = MappingParams(spacing=8.0)
    first, again = (
        map_world(world, replace(fake_encoder, noise=0.3, seed=1), params=params).cloud
        for _ in range(2)
    )
    np.testing.assert_array_equal(first.points, again.points)
    np.testing.assert_array_equal(first.embeddings, again.embeddings)


def test_bad_worlds_paths_and_parameters_are_refused(world, fake_encoder) -> None:
    with pytest.raises(InvalidInputError, match="no drive path"):
        map_world(generate_world("campus", "small"), fake_encoder)
    blocked = generate_world("outdoor", "small", seed=0)
    car = blocked.instances_of("car")[0]
    blocked.metadata["drive_path"] = [[2.0, car.centroid[1]], car.centroid[:2].tolist()]
    with pytest.raises(PlanningError, match="blocked"):
        map_world(blocked, fake_encoder)
    with pytest.raises(InvalidInputError, match="spacing"):
        make_mapping_params({"spacing": 0})
    with pytest.raises(InvalidInputError, match="radius"):
        make_mapping_params({"radius": "wide"})


def test_source_records_without_a_usable_world(fake_encoder) -> None:
    cloud = SemanticCloud.empty(fake_encoder.dim, fake_encoder.name)
    assert source_world(cloud) is None
    cloud.source = {"world": {"name": "outdoor", "seed": 0}}
    with pytest.raises(InvalidInputError, match="no usable world"):
        source_world(cloud)
