"""Gazebo SDF worlds and models: includes, model:// look-up, composed poses, scale, submeshes,
primitives, COLLADA meshes, a class map, and a warning naming what is not imported."""

from __future__ import annotations

import importlib.util
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh
import yaml

from seminspect.core.errors import FileFormatError
from seminspect.worlds import open_world
from seminspect.worlds.sdf import SiteWarning
from seminspect.worlds.site import load_site

TOYCAR_SDF = """<?xml version="1.0"?>
<sdf version="1.6">
  <model name="toycar">
    <static>true</static>
    <pose>0 0 0.5 0 0 0</pose>
    <link name="chassis">
      <collision name="hull"><geometry><box><size>2 4 1</size></box></geometry></collision>
      <visual name="body">
        <geometry><mesh>
          <uri>model://toycar/meshes/car.obj</uri><scale>0.5 0.5 0.5</scale>
          <submesh><name>Body</name></submesh>
        </mesh></geometry>
      </visual>
    </link>
    <link name="front_left_wheel">
      <pose>0.85 -1.3 0.3 0 0 0</pose>
      <visual name="wheel">
        <pose>0.1 0 0 0 0 0</pose>
        <geometry><mesh>
          <uri>model://toycar/meshes/car.obj</uri><scale>0.5 0.5 0.5</scale>
          <submesh><name>Wheel_FL</name><center>true</center></submesh>
        </mesh></geometry>
      </visual>
    </link>
    <joint name="axle" type="fixed"><parent>chassis</parent><child>front_left_wheel</child></joint>
    <plugin name="drive" filename="libdrive.so"/>
  </model>
</sdf>
"""
LOT_WORLD = """<?xml version="1.0"?>
<sdf version="1.6">
  <world name="lot">
    <light name="sun" type="directional"><pose>0 0 10 0 0 0</pose></light>
    <physics type="ode"><max_step_size>0.001</max_step_size></physics>
    <include><uri>model://ground_plane</uri></include>
    <include>
      <uri>model://toycar</uri><name>car-a</name><pose>5 0 0 0 0 1.5707963268</pose>
    </include>
    <include><uri>model://toycar</uri><name>car-b</name></include>
    <model name="post">
      <pose>0 8 1 0 0 0</pose>
      <link name="l">
        <visual name="pole"><geometry><cylinder><radius>0.2</radius><length>2</length></cylinder>
        </geometry></visual>
        <visual name="floor"><geometry><plane><normal>0 0 1</normal></plane></geometry></visual>
      </link>
    </model>
  </world>
</sdf>
"""
CLASSES = {"toycar": {"class": "car", "forward": "-y",
                      "parts": {"Body": "body", "Wheel_FL": "front-left-wheel"}}}  # fmt: skip


@pytest.fixture
def models(tmp_path: Path, car_obj) -> Path:
    """A GAZEBO_MODEL_PATH folder holding the toy car model, its OBJ at twice metres."""
    folder = tmp_path / "models" / "toycar"
    (folder / "meshes").mkdir(parents=True)
    shutil.move(car_obj(scale=0.5), folder / "meshes" / "car.obj")
    (folder / "model.config").write_text("<model><name>toycar</name><sdf>toy.sdf</sdf></model>")
    (folder / "toy.sdf").write_text(TOYCAR_SDF)
    return tmp_path / "models"


def _site(path: Path, **changes) -> Path:
    document = {"format": "seminspect-site", "version": 1, "name": "lot", "sdf": "lot.world",
                "classes": CLASSES, "ground": {"margin": 2, "z": 0}} | changes  # fmt: skip
    path.write_text(yaml.safe_dump(document))
    return path


def _centre(world, name: str, part: str) -> np.ndarray:
    mask = (world.face_instance == world.instance_named(name).id) & (
        world.face_part == world.part_id(part)
    )
    return world.mesh.vertices[np.unique(world.mesh.faces[mask])].mean(axis=0)


def test_a_gazebo_world_becomes_a_site(tmp_path, models, monkeypatch) -> None:
    monkeypatch.setenv("GAZEBO_MODEL_PATH", f"/nowhere:{models}")
    (tmp_path / "lot.world").write_text(LOT_WORLD)
    with pytest.warns(SiteWarning) as caught:
        world = load_site(_site(tmp_path / "site.yaml"))
    assert [i.name for i in world.instances.values()] == ["car-a", "car-b"]
    # car-a: the include's pose replaces the model's; turned 90 deg, its 4 m lie along x
    body = world.instance_named("car-a")
    assert body.bbox_min == pytest.approx([3.0, -1.0, 0.0]) and body.bbox_max[0] == pytest.approx(
        7.0
    )
    # the wheel: link pose + visual pose (0.95, -1.3, 0.3) turned 90 deg, the submesh centred
    assert _centre(world, "car-a", "front-left-wheel") == pytest.approx([6.3, 0.95, 0.3])
    # car-b keeps the model's own pose (0.5 m up), its front (-y) facing -y
    assert world.instance_named("car-b").bbox_min[2] == pytest.approx(0.5)
    assert world.metadata["headings"] == pytest.approx(
        {"car-a": 0.0, "car-b": -math.pi / 2}, abs=1e-9
    )
    # the post is a background cylinder 2 m high around (0, 8)
    pole = world.triangles[(world.face_instance == 0) & (world.face_class == 0)]
    assert np.ptp(pole[..., 2]) == pytest.approx(2.0) and pole[..., 1].mean() == pytest.approx(8)
    message = str(caught[0].message)
    for unread in ("world/light", "world/physics", "link/collision", "model/joint",
                   "model/plugin", "geometry/plane", "model://ground_plane",
                   "'post' (not in the class map"):  # fmt: skip
        assert unread in message
    assert "car-a" not in message  # what was read is not named


def test_models_are_found_beside_the_world_without_a_model_path(tmp_path, models, monkeypatch):
    monkeypatch.delenv("GAZEBO_MODEL_PATH", raising=False)
    (models / "lot.world").write_text(LOT_WORLD)  # model://toycar is in the world's folder
    with pytest.warns(SiteWarning):
        world = load_site(_site(models / "site.yaml"))
    assert {"car-a", "car-b"} <= {i.name for i in world.instances.values()}


def test_an_sdf_opens_as_a_world_with_the_class_map_beside_it(tmp_path, models, monkeypatch):
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(models))
    world_file = tmp_path / "lot.world"
    world_file.write_text(LOT_WORLD)
    with pytest.warns(SiteWarning) as caught:
        bare = open_world(str(world_file))
    assert "no class map (lot.classes.yaml)" in str(caught[0].message)
    assert not bare.instances and bare.name == "lot"
    (tmp_path / "lot.classes.yaml").write_text(yaml.safe_dump({"classes": CLASSES}))
    with pytest.warns(SiteWarning, match="not imported"):
        world = open_world(str(world_file))
    assert len(world.instances) == 2 and world.ground_z == 0.0


def test_a_target_model_that_cannot_be_found_is_an_error(tmp_path, models, monkeypatch) -> None:
    monkeypatch.delenv("GAZEBO_MODEL_PATH", raising=False)
    (tmp_path / "lot.world").write_text(LOT_WORLD)
    with pytest.raises(FileFormatError, match=r"include 'model://toycar'.*model not found"):
        load_site(_site(tmp_path / "site.yaml"))  # not skipped as 'model://ground_plane' is


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("<sdf><world", "malformed XML"),
        (LOT_WORLD.replace("5 0 0 0 0 1.5707963268", "5 0 0"), r"'5 0 0' is not 6 numbers"),
        (LOT_WORLD.replace("model://toycar</uri><name>car-a", "model://toycar/x</uri><name>a"),
         "model not found"),
        (LOT_WORLD.replace("<name>car-a</name>", "<name>car-b</name>"),
         "two models are called 'car-b'; give each <include> its own <name>"),
    ],
)  # fmt: skip
def test_a_broken_sdf_is_refused_in_one_line(tmp_path, models, monkeypatch, text, message):
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(models))
    (tmp_path / "lot.world").write_text(text)
    with pytest.raises(FileFormatError, match=message):
        load_site(_site(tmp_path / "site.yaml"))


def _write_dae(path: Path, unit: float) -> None:
    """A COLLADA file made with pycollada: one 2 x 4 x 1 box geometry named Hull."""
    import collada
    from collada import geometry, material, scene, source

    box = trimesh.creation.box(extents=(2.0, 4.0, 1.0))
    document = collada.Collada()
    effect = material.Effect("effect", [], "phong")
    paint = material.Material("paint", "paint", effect)
    document.effects.append(effect)
    document.materials.append(paint)
    points = source.FloatSource("points", np.asarray(box.vertices).ravel(), ("X", "Y", "Z"))
    hull = geometry.Geometry(document, "geom-Hull", "Hull", [points])
    inputs = source.InputList()
    inputs.addInput(0, "VERTEX", "#points")
    hull.primitives.append(hull.createTriangleSet(np.asarray(box.faces).ravel(), inputs, "m"))
    document.geometries.append(hull)
    node = scene.Node("node-Hull", children=[scene.GeometryNode(hull, [scene.MaterialNode(
        "m", paint, inputs=[])])])  # fmt: skip
    document.scenes.append(scene.Scene("scene", [node]))
    document.scene = document.scenes[0]
    document.assetInfo.unitmeter, document.assetInfo.unitname = unit, "unit"
    document.assetInfo.upaxis = "Z_UP"
    document.write(str(path))


DAE_MODEL = """<sdf version="1.6"><model name="van"><link name="l"><visual name="v"><geometry>
<mesh><uri>van.dae</uri></mesh></geometry></visual></link></model></sdf>"""


def test_a_collada_mesh_is_read_in_its_units(tmp_path) -> None:
    _write_dae(tmp_path / "van.dae", unit=0.5)
    (tmp_path / "van.sdf").write_text(DAE_MODEL)
    classes = {"van": {"class": "car", "parts": {"Hull": "body"}}}
    world = load_site(_site(tmp_path / "site.yaml", sdf="van.sdf", classes=classes))
    van = world.instance_named("van")
    assert (van.bbox_max - van.bbox_min) == pytest.approx([1.0, 2.0, 0.5]) and van.parts == ["body"]


def test_collada_without_pycollada_names_the_extra(tmp_path, monkeypatch) -> None:
    _write_dae(tmp_path / "van.dae", unit=1.0)
    (tmp_path / "van.sdf").write_text(DAE_MODEL)
    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "collada" else real(name, *a)
    )
    with pytest.raises(FileFormatError, match=r"van\.dae: .*pip install 'seminspect\[collada\]'"):
        load_site(_site(tmp_path / "site.yaml", sdf="van.sdf", classes={}))


def test_gazebo_prius_model_sdf_places_its_wheels(shared_data: Path, tmp_path: Path) -> None:
    """The shared Prius (CC-BY 3.0, OSRF gazebo_models) through its own model.sdf: chassis
    submeshes, centred wheel submeshes at their link poses, its front at -y."""
    source = shared_data / "vehicle_meshes_gazebo" / "prius_hybrid"
    model = tmp_path / "models" / "prius_hybrid"
    (model / "meshes").mkdir(parents=True)
    shutil.copy(source / "model.sdf", model / "model.sdf")
    (model / "meshes" / "Hybrid.obj").symlink_to(source / "Hybrid.obj")
    (tmp_path / "models" / "lot.world").write_text(
        '<sdf version="1.6"><world name="w"><include><uri>model://prius_hybrid</uri>'
        "<name>prius</name><pose>0 0 0 0 0 1.5707963268</pose></include></world></sdf>"
    )
    parts = {"Hybrid": "body", "Hybrid_Windows": "windows", "Hybrid_Interior": "interior",
             "Wheel_Front_Left_": "left-wheels", "Wheel_Front_Right": "right-wheels"}  # fmt: skip
    classes = {"prius_hybrid": {"class": "car", "forward": "-y", "parts": parts}}
    with pytest.warns(SiteWarning, match="link/inertial"):
        world = load_site(_site(tmp_path / "models" / "site.yaml", classes=classes))
    prius = world.instance_named("prius")
    size = prius.bbox_max - prius.bbox_min
    assert size[0] == pytest.approx(4.62, abs=0.05) and size[1] == pytest.approx(2.01, abs=0.05)
    assert world.metadata["headings"]["prius"] == pytest.approx(0.0, abs=1e-6)
    # turned 90 deg, the model's front-left wheel link (0.76 + 0.04, -1.41, 0.3) lies at x 1.41,
    # y 0.8; its rear-left wheel (the same submesh) at x -1.45: both left wheels on +y
    left = world.triangles[world.face_part == world.part_id("left-wheels")].mean(axis=1)
    assert np.all(left[:, 1] > 0.5)
    assert sorted(np.round([left[:, 0].min() + 0.3, left[:, 0].max() - 0.3], 0)) == [-1.0, 1.0]
    assert set(prius.parts) == {"body", "windows", "interior", "left-wheels", "right-wheels"}
