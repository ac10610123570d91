"""The four Gazebo vehicles of ../shared/data (CC-BY 3.0, OSRF gazebo_models) as one site file
written here, and a mission on it: the site's names, sizes along each heading, detections."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from cli_runner import run
from seminspect.worlds import open_world
from seminspect.worlds.pieces import size_along

WHEELS = "wheels"
#: mesh, class, name, scale, the mesh's front, position, yaw, parts (mesh group -> part)
VEHICLES = [
    ("prius_hybrid/Hybrid.obj", "car", "prius", 0.01, "-y", [-12, 0, 0], 0.0,
     {"Hybrid": "body", "Hybrid_Windows": "windows", "Hybrid_Interior": "interior",
      "Wheel_Front_Left_": WHEELS, "Wheel_Front_Right": WHEELS, "Wheels_Rear": WHEELS}),
    ("suv/suv.obj", "car", "suv", 0.06, "y", [0, 0, 0], 0.0,
     {"SUV": "body", "Wheel_Front_Left": WHEELS, "Wheel_Front_Right": WHEELS,
      "Wheel_Rear": WHEELS}),
    ("hatchback/hatchback.obj", "car", "hatchback", 0.0254, "-y", [12, 0, 0], 3.14159,
     {"Hatchback": "body", "Wheel_Front_Left_": WHEELS, "Wheel_Front_Right": WHEELS,
      "Wheels_Rear": WHEELS}),
    ("fire_truck/fire_truck.obj", "truck", "fire-truck", 0.1, "y", [0, 14, 0], 0.0,
     {"Firetruck": "body", "Wheel_Front_Left": WHEELS, "Wheel_Front_Right": WHEELS,
      "Wheel_Rear_01": WHEELS, "Wheel_Rear_02": WHEELS}),
]  # fmt: skip
#: Length and width in metres (the README's sizes of the shared models).
SIZES = {"prius": (4.62, 2.01), "suv": (5.0, 2.6), "hatchback": (4.0, 2.1),
         "fire-truck": (12.4, 3.5)}  # fmt: skip


@pytest.fixture
def gazebo_site(shared_data: Path, tmp_path: Path) -> Path:
    meshes = [
        {"path": str(shared_data / "vehicle_meshes_gazebo" / mesh), "class": cls,
         "instance": name, "scale": scale, "forward": forward, "position": position,
         "yaw": yaw, "parts": parts}
        for mesh, cls, name, scale, forward, position, yaw, parts in VEHICLES
    ]  # fmt: skip
    site = {"format": "seminspect-site", "version": 1, "name": "gazebo-lot",
            "ground": {"margin": 8, "z": 0}, "start": {"position": [-18, -8, 0], "yaw": 0},
            "meshes": meshes}  # fmt: skip
    path = tmp_path / "site.yaml"
    path.write_text(yaml.safe_dump(site, sort_keys=False))
    return path


def test_the_site_keeps_names_and_reads_lengths_along_headings(gazebo_site: Path) -> None:
    world = open_world(str(gazebo_site))
    assert [i.name for i in world.instances.values()] == ["prius", "suv", "hatchback",
                                                          "fire-truck"]  # fmt: skip
    for info in world.instances.values():
        length, width = size_along(world, info, world.metadata["headings"][info.name])
        assert (length, width) == pytest.approx(SIZES[info.name], abs=0.1)
        # yaw 0 or 180 deg: the world's x extent is the length
        assert info.bbox_max[0] - info.bbox_min[0] == pytest.approx(length)
        assert {"body", WHEELS} <= set(info.parts)
    assert world.instance_named("fire-truck").class_name == "truck"


def test_world_check_and_show_on_the_site(capsys, gazebo_site: Path, tmp_path: Path) -> None:
    code, out, _ = run(capsys, "world", "check", str(gazebo_site))
    assert code == 0 and "ready" in out and "error:" not in out
    assert "windows are not in the built-in vocabulary" in out.replace("\n", " ")
    code, out, _ = run(capsys, "world", "show", str(gazebo_site), "-o", str(tmp_path / "s.png"))
    assert code == 0
    rows = {cells[1].strip(): cells for cells in (line.split("│") for line in out.splitlines())
            if len(cells) > 6}  # fmt: skip
    for name, (length, width) in SIZES.items():  # object, class, x, y, length, width, ...
        assert float(rows[name][5]) == pytest.approx(length, abs=0.1)
        assert float(rows[name][6]) == pytest.approx(width, abs=0.1)


@pytest.mark.slow
def test_a_mission_on_the_site_detects_and_inspects_every_vehicle(
    capsys, gazebo_site: Path, tmp_path: Path
) -> None:
    """The default mission (it ends by itself, no target or frontier left, in about 280 s
    simulated); 300 s of budget is a limit only."""
    out = tmp_path / "run"
    code, text, _ = run(capsys, "mission", "--world", str(gazebo_site), "--budget", "300",
                        "--no-pictures", "--out", str(out))  # fmt: skip
    assert code == 0 and "completed" in text
    metrics = json.loads((out / "metrics.json").read_text())
    truths = sorted(match["truth"] for match in metrics["targets"]["matches"])
    assert truths == sorted(SIZES)  # the site's names, each matched by a detection
    assert metrics["table3"]["detected_pct"] == 100.0


def test_the_documented_site_file_loads(shared_data: Path, tmp_path: Path) -> None:
    """docs/sites.md's first example, saved beside the shared vehicle folder, as it says."""
    docs = (Path(__file__).resolve().parents[2] / "docs" / "sites.md").read_text()
    (tmp_path / "site.yaml").write_text(docs.split("```yaml\n", 1)[1].split("```", 1)[0])
    (tmp_path / "vehicle_meshes_gazebo").symlink_to(shared_data / "vehicle_meshes_gazebo")
    world = open_world(str(tmp_path / "site.yaml"))
    for info in world.instances.values():
        length, width = size_along(world, info, world.metadata["headings"][info.name])
        assert (length, width) == pytest.approx(SIZES[info.name], abs=0.1)
    assert list(SIZES) == [i.name for i in world.instances.values()]
