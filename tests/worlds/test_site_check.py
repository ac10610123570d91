"""``check_world``: what a site gets wrong before any mission, each finding with its level."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from seminspect.worlds import generate_world
from seminspect.worlds.site import load_site
from seminspect.worlds.site_check import check_world

CAR = {"path": "car.obj", "class": "car", "forward": "-y",
       "parts": {"Body": "body", "Wheel_FL": "front-left-wheel"}}  # fmt: skip


def _world(tmp_path: Path, meshes: list[dict], **changes):
    document = {"format": "seminspect-site", "version": 1, "ground": {"margin": 4, "z": 0},
                "start": {"position": [-4, -3, 0]}, "meshes": meshes} | changes  # fmt: skip
    (tmp_path / "site.yaml").write_text(yaml.safe_dump(document))
    return load_site(tmp_path / "site.yaml")


def _found(world, classes=("car", "truck")) -> list[tuple[str, str]]:
    return [(f.level, f.message) for f in check_world(world, classes)]


def test_a_good_site_has_no_findings(tmp_path, car_obj) -> None:
    car_obj()
    world = _world(
        tmp_path, [CAR | {"instance": "a"}, CAR | {"instance": "b", "position": [0, 5, 0]}]
    )
    assert _found(world) == []


@pytest.mark.parametrize(
    ("meshes", "changes", "expected"),
    [
        ([CAR | {"instance": "a"}, CAR | {"instance": "b", "position": [1, 0.5, 0]}], {},
         ("error", "a and b overlap")),
        ([CAR | {"instance": "a"}], {"start": {"position": [0, 0, 0]}},
         ("error", "inside an obstacle or within 0.4 m of one")),
        ([CAR | {"instance": "a"}], {"start": {"position": [40, 0, 0]}},
         ("error", "outside the bounds")),
        ([CAR | {"instance": "a"}], {"start": {"position": [-4, -3, 0.5]}},
         ("error", "is not on the ground (z = 0.000)")),
        ([CAR | {"class": "kiosk", "instance": "k"}], {}, ("error", "no targets (car, truck)")),
        ([CAR | {"instance": "a", "forward": "x"}], {},
         ("warning", "a: its long axis lies 90 deg across its heading 0 deg")),
        ([CAR | {"instance": "a", "parts": None}], {}, ("warning", "a has no parts")),
        ([CAR | {"instance": "a", "parts": {"Body": "body", "Wheel_FL": "hubcap"}}], {},
         ("warning", "parts hubcap are not in the built-in vocabulary")),
    ],
)  # fmt: skip
def test_each_problem_is_found(tmp_path, car_obj, meshes, changes, expected) -> None:
    level, words = expected
    car_obj()
    meshes = [{k: v for k, v in m.items() if v is not None} for m in meshes]
    findings = _found(_world(tmp_path, meshes, **changes))
    assert [f for f in findings if words in f[1]] != [], findings
    assert all(found == level for found, message in findings if words in message)


def test_built_in_worlds_pass_their_own_check() -> None:
    assert _found(generate_world("campus", "small")) == []
    assert _found(generate_world("collapsed-buildings"), ("building",)) == []
