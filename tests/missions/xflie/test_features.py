"""Feature labels come from the world: parts outside the built-in vocabulary are recorded, and
a configured list that leaves parts out, or names parts no target carries, is warned about."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
import trimesh
import yaml

from seminspect.core.errors import InvalidInputError
from seminspect.core.vocabulary import BUILDING_FEATURES, VEHICLE_PARTS
from seminspect.missions.xflie.build import build_mission
from seminspect.missions.xflie.config import make_config, resolve
from seminspect.missions.xflie.features import FeatureWarning, world_feature_labels
from seminspect.missions.xflie.run import run_mission
from seminspect.planning.query import parse_query, resolve_query
from seminspect.worlds import World, WorldBuilder, open_world, save_world
from seminspect.worlds.shapes import box

WHEELS = ("front-left-wheel", "front-right-wheel", "back-left-wheel", "back-right-wheel")
#: A car as the Gazebo models name its parts: body, windows, interior and wheels, as boxes
#: (lower and upper corners, metres) that a ground robot's camera sees from the side.
CAR_PARTS = {
    "body": ((-2.25, -0.95, 0.3), (2.25, 0.95, 1.0)),
    "windows": ((-0.6, -0.85, 1.0), (1.2, 0.85, 1.5)),
    "interior": ((-2.0, -0.85, 1.0), (-0.6, 0.85, 1.3)),
    "front-left-wheel": ((1.1, 0.95, 0.0), (1.8, 1.2, 0.7)),
    "front-right-wheel": ((1.1, -1.2, 0.0), (1.8, -0.95, 0.7)),
    "back-left-wheel": ((-1.8, 0.95, 0.0), (-1.1, 1.2, 0.7)),
    "back-right-wheel": ((-1.8, -1.2, 0.0), (-1.1, -0.95, 0.7)),
}


def write_car_site(folder: Path) -> Path:
    """A mesh of one boxy car (trimesh) and its labels file: the car is ``my-car``."""
    folder.mkdir(parents=True, exist_ok=True)
    meshes, labels, start = [], [], 0
    for part, (lower, upper) in CAR_PARTS.items():
        lo, hi = np.array(lower), np.array(upper)
        mesh = trimesh.creation.box(extents=hi - lo)
        mesh.apply_translation((lo + hi) / 2)
        faces = [[start, start + len(mesh.faces)]]
        labels.append({"faces": faces, "instance": "my-car", "class": "car", "part": part})
        start += len(mesh.faces)
        meshes.append(mesh)
    trimesh.util.concatenate(meshes).export(folder / "car.ply")
    document = {
        "format": "seminspect-world-labels",
        "version": 1,
        "name": "lot",
        "ground": {"margin": 10},
        "start": {"position": [-8.0, 0.0, 0.0], "yaw": 0.0},
        "labels": labels,
    }
    (folder / "labels.yaml").write_text(yaml.safe_dump(document))
    return folder


@pytest.fixture(scope="module")
def car_site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_car_site(tmp_path_factory.mktemp("site") / "lot")


@pytest.mark.parametrize(
    ("world", "scenario", "expected"),
    [
        ("city", "small", VEHICLE_PARTS),
        ("campus", "small", VEHICLE_PARTS),
        ("subterranean", None, VEHICLE_PARTS),
        ("collapsed-buildings", "fire-station", BUILDING_FEATURES),
        ("collapsed-buildings", "industrial", BUILDING_FEATURES),
    ],
)
def test_a_built_in_worlds_parts_are_its_published_vocabulary(world, scenario, expected) -> None:
    """The built-in worlds keep the feature list their published runs used, in its order."""
    config = resolve(make_config({"world": world, "scenario": scenario}))
    assert config.feature_labels == expected
    derived = world_feature_labels(open_world(world, scenario), config.target_classes)
    assert derived == expected


def test_a_user_worlds_features_are_its_targets_parts_but_the_body(car_site) -> None:
    config = resolve(make_config({"world": str(car_site)}))
    assert config.feature_labels == (*WHEELS, "interior", "windows")
    assert resolve(config) == config  # the resolved list stays as it is


def test_the_derived_labels_start_a_mission_without_a_word(car_site) -> None:
    config = resolve(make_config({"world": str(car_site)}))
    with warnings.catch_warnings():
        warnings.simplefilter("error", FeatureWarning)
        build_mission(config, None)


def test_labels_that_leave_out_world_parts_say_which_and_how_to_include_them(car_site) -> None:
    config = resolve(make_config({"world": str(car_site), "feature_labels": list(WHEELS)}))
    with pytest.warns(FeatureWarning, match="ignored: interior, windows; add them to") as caught:
        build_mission(config, None)
    assert len([w for w in caught if w.category is FeatureWarning]) == 1


def test_labels_that_name_no_part_of_the_targets_are_named(car_site) -> None:
    labels = ["hood", *WHEELS, "interior", "windows"]
    config = resolve(make_config({"world": str(car_site), "feature_labels": labels}))
    with pytest.warns(FeatureWarning, match="no target carries the feature labels hood, so"):
        build_mission(config, None)


def test_a_configured_label_the_graph_could_not_hold_is_refused_at_once() -> None:
    with pytest.raises(InvalidInputError, match="feature_labels: invalid semantic label 'a/b'"):
        make_config({"feature_labels": ["windows", "a/b"]})


def one_car(*parts: str) -> World:
    """A world of one car made of a 1 m box per part."""
    builder = WorldBuilder("odd")
    builder.add_ground((-5.0, -5.0), (5.0, 5.0))
    builder.add_object([box((i, 0, 0), (i + 1, 1, 1), part) for i, part in enumerate(parts)], "car")
    return builder.build([(-5.0, -5.0, 0.0), (5.0, 5.0, 3.0)], (-4.0, 0.0, 0.0))


def test_part_names_that_cannot_name_a_feature_are_left_out_aloud() -> None:
    world = one_car("body", "2nd/mirror", "mirror")
    with pytest.warns(FeatureWarning, match="'2nd/mirror' cannot name features"):
        assert world_feature_labels(world, ["car"]) == ("mirror",)


def test_targets_with_no_parts_to_record_say_so(tmp_path: Path) -> None:
    save_world(one_car("body", "roof"), tmp_path / "plain")
    config = resolve(make_config({"world": str(tmp_path / "plain")}))
    assert config.feature_labels == ()
    with pytest.warns(FeatureWarning, match="no parts besides body, roof, wall, so no features"):
        build_mission(config, None)


@pytest.fixture(scope="module")
def car_site_run(car_site: Path, tmp_path_factory: pytest.TempPathFactory):
    config = make_config({"world": str(car_site), "noise": "ideal", "time_budget_s": 300})
    return run_mission(config, tmp_path_factory.mktemp("run") / "lot")


@pytest.mark.slow
def test_the_mission_records_the_worlds_own_parts(car_site_run) -> None:
    assert car_site_run.state == "completed"
    (car,) = car_site_run.mission.graph.targets()
    labels = {f.label for level in car.levels for pose in level.poses for f in pose.features}
    assert {"windows", "interior"} <= labels
    assert labels <= {*WHEELS, "windows", "interior"}
    window = next(f for p in car.levels[0].poses for f in p.features if f.label == "windows")
    query = parse_query(f"Visit {window.name} in Level-0 of {car.id}")
    assert resolve_query(car_site_run.mission.graph, query) == window.id


@pytest.mark.slow
def test_the_summary_names_the_site_object_each_target_matched(car_site_run) -> None:
    summary = (car_site_run.run_dir / "summary.md").read_text()
    (car,) = car_site_run.mission.graph.targets()
    assert "| Target | Site object | Status |" in summary
    assert f"| {car.id} | my-car | inspected |" in summary
