import json
import math
import time
from pathlib import Path

import numpy as np
import pytest
import trimesh
import yaml

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.worlds import generate_world, insert_world, load_world, save_world

CUBE_OBJ = """# two unit cubes, the second one in two groups
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
g Body
f 1 3 2
f 1 4 3
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
f 5 6 7 8
g Wheel
f -8 -6 -7
"""


def _labels(**changes) -> dict:
    document = {
        "format": "seminspect-world-labels",
        "version": 1,
        "name": "cubes",
        "ground": {"margin": 3.0},
        "labels": [
            {"groups": ["Body"], "instance": "cart-1", "class": "cart", "part": "body"},
            {"groups": ["Wheel"], "instance": "cart-1", "class": "cart", "part": "wheel"},
            {
                "groups": ["Body"],
                "box": [[0, 0, 0.9], [1, 1, 1.1]],
                "instance": "cart-1",
                "class": "cart",
                "part": "lid",
            },
        ],
    }
    return document | changes


@pytest.fixture
def cube_files(tmp_path: Path) -> tuple[Path, Path]:
    mesh = tmp_path / "cubes.obj"
    mesh.write_text(CUBE_OBJ)
    labels = tmp_path / "labels.yaml"
    labels.write_text(yaml.safe_dump(_labels()))
    return mesh, labels


def test_obj_groups_polygons_boxes_and_overrides(cube_files) -> None:
    world = load_world(*cube_files)
    assert len(world.mesh.faces) == 2 + 5 * 2 + 1 + 2  # quads split into two triangles + ground
    cart = world.instance_named("cart-1")
    assert cart.parts == ["body", "lid", "wheel"] and cart.class_name == "cart"
    lid = world.face_part == world.part_id("lid")
    assert lid.sum() == 2 and np.allclose(world.triangles[lid][..., 2], 1.0)
    assert (world.face_part == world.part_id("wheel")).sum() == 1
    assert (world.face_class == world.class_id("ground")).sum() == 2
    np.testing.assert_allclose(world.bounds, [[-3, -3, 0], [4, 4, 3]])


def test_saved_worlds_reload_exactly(tmp_path: Path) -> None:
    world = generate_world("campus", "small", seed=1)
    save_world(world, tmp_path / "out")
    again = load_world(tmp_path / "out" / "world.ply", tmp_path / "out" / "labels.json")
    np.testing.assert_array_equal(world.mesh.vertices, again.mesh.vertices)
    np.testing.assert_array_equal(world.mesh.faces, again.mesh.faces)
    for field in ("face_instance", "face_class", "face_part"):
        names = {"face_class": "class_names", "face_part": "part_names"}.get(field)
        if names:
            before = np.array(getattr(world, names))[getattr(world, field)]
            after = np.array(getattr(again, names))[getattr(again, field)]
            np.testing.assert_array_equal(before, after)
    assert [i.name for i in world.instances.values()] == [i.name for i in again.instances.values()]
    np.testing.assert_array_equal(world.bounds, again.bounds)
    np.testing.assert_array_equal(world.start_position, again.start_position)
    assert again.metadata["scenario"] == "small"


def test_saved_worlds_keep_their_ground_height(tmp_path: Path) -> None:
    # rubble sinks below the ground, so the mesh's lowest point is not the ground
    world = generate_world("collapsed-buildings", "fire-station")
    assert world.mesh.vertices[:, 2].min() < -0.05
    save_world(world, tmp_path)
    again = load_world(tmp_path / "world.ply", tmp_path / "labels.json")
    assert again.ground_z == world.ground_z == 0.0
    points = np.random.default_rng(0).uniform([0, 0, 0.7], [80, 56, 0.7], (2000, 3))
    np.testing.assert_array_equal(
        world.clearance(points, "ground"), again.clearance(points, "ground")
    )


def test_glb_node_names_select_faces(tmp_path: Path) -> None:
    scene = trimesh.Scene()
    scene.add_geometry(trimesh.creation.box((1, 1, 1)), node_name="chassis", geom_name="m0")
    scene.add_geometry(
        trimesh.creation.box((0.2, 0.2, 0.2)),
        node_name="lamp",
        geom_name="m1",
        transform=trimesh.transformations.translation_matrix((0, 0, 2)),
    )
    mesh = tmp_path / "thing.glb"
    mesh.write_bytes(scene.export(file_type="glb"))
    labels = tmp_path / "labels.json"
    labels.write_text(
        json.dumps(
            _labels(
                up="z",
                labels=[
                    {
                        "groups": ["chassis"],
                        "instance": "robot-1",
                        "class": "robot",
                        "part": "body",
                    },
                    {"groups": ["m1"], "instance": "robot-1", "class": "robot", "part": "lamp"},
                ],
            )
        )
    )
    world = load_world(mesh, labels)
    lamp = world.face_part == world.part_id("lamp")
    assert lamp.sum() == 12 and world.triangles[lamp][..., 2].min() > 1.8


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"format": "other"}, "format"),
        ({"version": 2}, "version"),
        ({"labels": [{"groups": ["Nope"], "class": "x"}]}, "no mesh group 'Nope'"),
        ({"labels": [{"faces": [[0, 99]], "class": "x"}]}, "exceeds the 13 faces"),
        ({"labels": [{"faces": [[3, 1]], "class": "x"}]}, "start <= stop"),
        ({"labels": [{"groups": ["Body"], "box": [[5, 5, 5], [6, 6, 6]]}]}, "selects no faces"),
        ({"labels": [{"groups": ["Body"], "colour": "red"}]}, "colour"),
        ({"scale": -1}, "scale"),
        (
            {
                "labels": [
                    {"groups": ["Body"], "instance": "a", "class": "cart"},
                    {"groups": ["Wheel"], "instance": "a", "class": "bike"},
                ]
            },
            "classes",
        ),
        ({"labels": [{"groups": ["Body"], "instance": "a", "class": "ground"}]}, "reserved"),
    ],
)
def test_bad_labels_name_the_problem(cube_files, change, message) -> None:
    mesh, labels = cube_files
    labels.write_text(yaml.safe_dump(_labels(**change)))
    with pytest.raises(FileFormatError, match=message):
        load_world(mesh, labels)


@pytest.mark.parametrize(
    ("mesh_text", "labels_text", "suffix", "message"),
    [
        (CUBE_OBJ, "labels: [unclosed", ".yaml", "malformed YAML"),
        (CUBE_OBJ, "{not json", ".json", "malformed JSON"),
        (
            CUBE_OBJ.replace("f -8 -6 -7", "f 1 2 99"),
            None,
            ".yaml",
            r"cubes.obj:\d+: vertex index 99",
        ),
        (CUBE_OBJ.replace("v 0 0 0", "v 0 zero 0"), None, ".yaml", "could not convert"),
        ("# nothing\n", None, ".yaml", "no faces"),
    ],
)
def test_bad_files_name_the_problem(tmp_path, mesh_text, labels_text, suffix, message) -> None:
    mesh = tmp_path / "cubes.obj"
    mesh.write_text(mesh_text)
    labels = tmp_path / f"labels{suffix}"
    labels.write_text(labels_text or yaml.safe_dump(_labels()))
    with pytest.raises(FileFormatError, match=message):
        load_world(mesh, labels)


def test_missing_and_unsupported_files(tmp_path, cube_files) -> None:
    mesh, labels = cube_files
    with pytest.raises(FileFormatError, match="no such file"):
        load_world(tmp_path / "none.obj", labels)
    with pytest.raises(FileFormatError, match="no such file"):
        load_world(mesh, tmp_path / "none.yaml")
    odd = tmp_path / "mesh.xyz"
    odd.write_text("1 2 3")
    with pytest.raises(FileFormatError, match="unsupported mesh type"):
        load_world(odd, labels)
    broken = tmp_path / "broken.glb"
    broken.write_bytes(b"glTF not really")
    with pytest.raises(FileFormatError, match=r"broken\.glb"):
        load_world(broken, labels)
    with pytest.raises(InvalidInputError, match="not a directory"):
        save_world(load_world(mesh, labels), mesh)


def test_a_world_can_be_placed_inside_another(cube_files) -> None:
    base = generate_world("campus", "small", seed=0)
    item = load_world(*cube_files)  # its ground plane comes along as ground
    merged = insert_world(base, item, (20.0, 12.0, 0.0), yaw=math.pi / 2)
    assert len(merged.instances) == len(base.instances) + 1
    cart = merged.instance_named("cart-1")
    assert cart.bbox_min[0] == pytest.approx(19.0) and cart.bbox_min[1] == pytest.approx(12.0)
    twice = insert_world(merged, item, (30.0, 12.0, 0.0))
    assert {"cart-1", "cart-2"} <= {i.name for i in twice.instances.values()}


def test_gazebo_prius_wheels_keep_their_labels(shared_data: Path, tmp_path: Path) -> None:
    """The Prius model (CC-BY 3.0, OSRF gazebo_models) placed on a campus: wheels by ray."""
    mesh = shared_data / "vehicle_meshes_gazebo" / "prius_hybrid" / "Hybrid.obj"
    labels = tmp_path / "prius.yaml"
    car = {"instance": "prius-1", "class": "car"}
    labels.write_text(
        yaml.safe_dump(
            _labels(
                name="prius",
                scale=0.01,
                ground=None,
                labels=[
                    {
                        "groups": ["Hybrid", "Hybrid_Interior", "Steering_Wheel"],
                        "part": "body",
                        **car,
                    },
                    {"groups": ["Hybrid_Windows"], "part": "front-glass", **car},
                    {"groups": ["Wheel_Front_Left_"], "part": "front-left-wheel", **car},
                    {"groups": ["Wheel_Front_Right"], "part": "front-right-wheel", **car},
                    {
                        "groups": ["Wheels_Rear"],
                        "box": [[0, -9, -1], [9, 9, 9]],
                        "part": "back-left-wheel",
                        **car,
                    },
                    {
                        "groups": ["Wheels_Rear"],
                        "box": [[-9, -9, -1], [0, 9, 9]],
                        "part": "back-right-wheel",
                        **car,
                    },
                ],
            )
        )
    )
    prius = load_world(mesh, labels)
    info = prius.instance_named("prius-1")
    size = info.bbox_max - info.bbox_min
    assert size[1] == pytest.approx(4.62, abs=0.05) and size[0] == pytest.approx(2.01, abs=0.05)
    # The model's nose points to -y; turned by +90 deg it points to +x, its left side to +y.
    world = insert_world(generate_world("campus", "small"), prius, (20.0, 12.0, 0.0), math.pi / 2)
    wheel_x = {"front": 20.0 + 1.42, "back": 20.0 - 1.45}
    for end, x in wheel_x.items():
        for side, y0, dy in (("left", 14.5, -1.0), ("right", 9.5, 1.0)):
            _, face = world.raycaster.cast((x, y0, 0.3), np.array([[0, dy, 0]], np.float32))
            assert world.instances[world.face_instance[face[0]]].name == "prius-1"
            assert world.part_names[world.face_part[face[0]]] == f"{end}-{side}-wheel"


def test_a_world_path_names_a_folder_a_labels_file_or_a_mesh(tmp_path) -> None:
    from seminspect.core.errors import FileFormatError
    from seminspect.worlds import generate_world, open_world, save_world

    folder = save_world(generate_world("subterranean"), tmp_path / "tunnel")
    names = {w.name for w in (open_world(str(folder)), open_world(str(folder / "labels.json")))}
    names.add(open_world(str(folder / "world.ply")).name)
    assert names == {generate_world("subterranean").name}
    (folder / "copy.obj").write_text("v 0 0 0\n")
    with pytest.raises(FileFormatError, match=r"exactly one mesh .*copy\.obj, world\.ply"):
        open_world(str(folder))
    with pytest.raises(FileFormatError, match="no such world file"):
        open_world(str(tmp_path / "gone"))


def test_a_world_at_the_wrong_scale_is_refused_before_its_grids(cube_files) -> None:
    """A mesh in metres labelled as micrometres: 35 s to a MemoryError before this check."""
    mesh, labels = cube_files
    document = _labels(scale=1e6)
    document["labels"] = document["labels"][:2]  # the lid's box is in metres
    labels.write_text(yaml.safe_dump(document))
    started = time.perf_counter()
    with pytest.raises(FileFormatError) as caught:
        load_world(mesh, labels)
    assert time.perf_counter() - started < 5.0
    message = str(caught.value)
    assert message.startswith(f"{labels}: the world is 1e+06 x 1e+06 x")
    assert "ground collision grid would have 4e+14 cells at 0.05 m" in message
    assert "'scale: 1e+06'" in message and "smaller scale" in message
    assert "\n" not in message
