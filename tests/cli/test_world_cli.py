import json

import pytest

from cli_runner import run
from seminspect.worlds import load_world


def test_list_shows_every_world(capsys) -> None:
    code, out, _ = run(capsys, "world", "list")
    assert code == 0
    for name in ("city", "collapsed-buildings", "campus", "subterranean", "mine-drift", "room",
                 "outdoor"):  # fmt: skip
        assert name in out


def test_show_draws_and_lists_objects(capsys, tmp_path) -> None:
    target = tmp_path / "campus.png"
    code, out, _ = run(
        capsys, "world", "show", "campus", "-s", "small", "--seed", "2", "-o", str(target)
    )
    assert code == 0 and target.read_bytes()[:4] == b"\x89PNG"
    assert "car-3" in out and "wrote" in out


def test_export_writes_a_loadable_world(capsys, tmp_path) -> None:
    code, out, _ = run(capsys, "world", "export", "subterranean", "--out", str(tmp_path / "w"))
    assert code == 0 and "world.ply" in out
    world = load_world(tmp_path / "w" / "world.ply", tmp_path / "w" / "labels.json")
    assert [i.name for i in world.instances.values()] == ["car-1"]
    labels = json.loads((tmp_path / "w" / "labels.json").read_text())
    assert labels["format"] == "seminspect-world-labels" and labels["metadata"]["generator"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("world", "show", "citty"), "did you mean 'city'"),
        (("world", "show", "city", "--scenario", "huge"), "unknown city scenario 'huge'"),
    ],
)
def test_errors_are_one_line_and_non_zero(capsys, args, message) -> None:
    code, _, err = run(capsys, *args)
    assert code == 1
    assert message in err and err.count("\n") == 1 and "Traceback" not in err
