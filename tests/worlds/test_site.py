"""Site files: several meshes placed by position, yaw, scale and forward axis in one world."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from seminspect.core.errors import FileFormatError
from seminspect.worlds import open_world
from seminspect.worlds.pieces import size_along
from seminspect.worlds.site import load_site, missing_files

PARTS = {"Body": "body", "Wheel_FL": "front-left-wheel", "Wheel_FR": "front-right-wheel",
         "Wheels_Rear": "wheels"}  # fmt: skip


def _site(tmp_path: Path, meshes: list[dict], **changes) -> Path:
    document = {
        "format": "seminspect-site",
        "version": 1,
        "name": "lot",
        "ground": {"margin": 3, "z": 0},
        "meshes": meshes,
    } | changes
    path = tmp_path / "site.yaml"
    path.write_text(yaml.safe_dump(document, sort_keys=False))
    return path


def _car(path: str = "car.obj", **changes) -> dict:
    return {"path": path, "class": "car", "forward": "-y", "parts": PARTS} | changes


def _faces_of(world, name: str, part: str) -> np.ndarray:
    """Centroids of the faces of one object's part."""
    mask = (world.face_instance == world.instance_named(name).id) & (
        world.face_part == world.part_id(part)
    )
    return world.triangles[mask].mean(axis=1)


def test_names_are_kept_and_each_mesh_is_placed_facing_its_yaw(tmp_path, car_obj) -> None:
    car_obj()
    site = _site(
        tmp_path,
        [
            _car(instance="zeta-9", position=[0, 0, 0], yaw=0.0),
            _car(instance="car-0", position=[10, 0, 0], yaw=math.pi / 2),
            _car(instance="alpha", position=[0, 10, 0], yaw=math.pi),
        ],
    )
    world = open_world(str(site))
    assert [i.name for i in world.instances.values()] == ["zeta-9", "car-0", "alpha"]
    first, second = world.instance_named("zeta-9"), world.instance_named("car-0")
    # yaw 0: the front (the mesh's -y) faces +x, so the 4 m length lies along x
    size = first.bbox_max - first.bbox_min
    assert size[0] == pytest.approx(4.0) and size[1] == pytest.approx(2.0)
    assert _faces_of(world, "zeta-9", "front-left-wheel")[:, 0].mean() == pytest.approx(1.3)
    assert _faces_of(world, "zeta-9", "front-left-wheel")[:, 1].mean() == pytest.approx(0.85)
    # yaw 90 deg: the front faces +y; the length lies along y
    assert size_along(world, second, math.pi / 2) == pytest.approx((4.0, 2.0))
    assert (second.bbox_max - second.bbox_min)[1] == pytest.approx(4.0)
    assert _faces_of(world, "car-0", "front-left-wheel")[:, 1].mean() == pytest.approx(1.3)
    assert _faces_of(world, "alpha", "front-left-wheel")[:, 0].mean() == pytest.approx(-1.3)
    assert world.metadata["headings"] == {"zeta-9": 0.0, "car-0": math.pi / 2, "alpha": math.pi}
    assert set(first.parts) == {"body", "front-left-wheel", "front-right-wheel", "wheels"}
    assert world.ground_z == 0.0 and world.start_position[2] == 0.0


def test_scale_up_axis_and_labels_entries_inherit_the_object(tmp_path, car_obj) -> None:
    car_obj("cm.obj", scale=0.01)
    rear = {"groups": ["Wheels_Rear"], "box": [[-9, -9, -1], [9, 0, 9]], "part": "back-right"}
    meshes = [
        {"path": "cm.obj", "class": "car", "instance": "c", "scale": 0.01, "forward": "-y",
         "labels": [{"groups": ["Body"], "part": "body"}, rear]},
        {"path": "cm.obj", "class": "wall", "scale": [0.02, 0.01, 0.01], "position": [0, 8, 0]},
    ]  # fmt: skip
    world = load_site(_site(tmp_path, meshes))
    car = world.instance_named("c")
    assert (car.bbox_max - car.bbox_min) == pytest.approx([4.0, 2.0, 1.5])
    # the box is in the object's frame (front along +x): the rear wheels' right half (y < 0)
    assert _faces_of(world, "c", "back-right")[:, 1].max() < 0.0
    assert sorted(car.parts) == ["back-right", "body"]
    # a mesh without instance is background geometry of its class, here 4 m wide
    walls = world.triangles[world.face_class == world.class_id("wall")]
    assert len(world.instances) == 1 and np.ptp(walls[..., 0]) == pytest.approx(4.0)


def test_a_y_up_mesh_stands_up(tmp_path, car_obj) -> None:
    path = car_obj()
    lines = []
    for line in path.read_text().splitlines():  # z-up (x, y, z) written as y-up (x, z, -y)
        if line.startswith("v "):
            x, y, z = map(float, line.split()[1:])
            lines.append(f"v {x} {z} {-y}")
        else:
            lines.append(line)
    path.write_text("\n".join(lines))
    world = load_site(_site(tmp_path, [_car(instance="c", up="y")]))
    info = world.instance_named("c")
    assert info.height == pytest.approx(1.5) and (info.bbox_max - info.bbox_min)[0] == 4.0


@pytest.mark.parametrize(
    ("meshes", "message"),
    [
        ([_car(instance="a"), _car(instance="a", position=[9, 0, 0])],
         r"meshes\[1\]: instance 'a' is already meshes\[0\]'s"),
        ([_car(instance="a", parts={"Wheelz": "wheels"})],
         r"meshes\[0\]\.parts\[0\]: no mesh group 'Wheelz'; the mesh has .*'Body'"),
        ([_car(instance="a", labels=[{"groups": ["Body"]}])], "give 'labels' or 'parts', not both"),
        ([_car("gone.obj", instance="a")], r"meshes\[0\]\.path: no such file .*gone\.obj"),
        ([_car(instance="a", yaw="east")], r"meshes\.0\.yaw"),
        ([_car(instance="a", scale=0)], "scale must be positive"),
        ([], "places no meshes"),
    ],
)  # fmt: skip
def test_a_bad_site_is_refused_in_one_line(tmp_path, car_obj, meshes, message) -> None:
    car_obj()
    site = _site(tmp_path, meshes)
    with pytest.raises(FileFormatError, match=message) as caught:
        load_site(site)
    assert str(site) in str(caught.value) and "\n" not in str(caught.value)


def test_missing_files_lists_every_mesh_not_found(tmp_path, car_obj) -> None:
    car_obj()
    site = _site(tmp_path, [_car("a.obj"), _car(), _car("b.obj")], sdf="lot.world")
    found = missing_files(site)
    assert len(found) == 3
    assert "meshes[0].path" in found[0] and "a.obj" in found[0] and "sdf" in found[2]


def test_a_labels_file_is_still_a_labels_file(tmp_path, car_obj) -> None:
    """A single-mesh labels file beside its mesh loads as before, not as a site."""
    car_obj()
    labels = {"format": "seminspect-world-labels", "version": 1, "name": "one",
              "labels": [{"groups": ["Body"], "instance": "car-1", "class": "car"}]}  # fmt: skip
    (tmp_path / "labels.yaml").write_text(yaml.safe_dump(labels))
    world = open_world(str(tmp_path / "labels.yaml"))
    assert world.name == "one" and "headings" not in world.metadata


def test_an_octomap_is_named_a_map_not_a_world(tmp_path) -> None:
    octomap = tmp_path / "geb079.bt"
    octomap.write_bytes(b"# Octomap OcTree binary file\n")
    with pytest.raises(FileFormatError, match="an OctoMap is a map, not a world") as caught:
        open_world(str(octomap))
    assert "routine inspect --prior" in str(caught.value) and "seminspect plan" in str(caught.value)
