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


def _site(tmp_path, start, *, second=(8.0, 0.0)) -> str:
    """A site of two 4 x 2 m boxes labelled as cars, written as an OBJ and a site file."""
    import trimesh
    import yaml

    box = trimesh.creation.box(extents=(4.0, 2.0, 1.5))
    box.apply_translation((0.0, 0.0, 0.75))
    lines = [f"v {x} {y} {z}" for x, y, z in box.vertices] + ["g Shell"]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in box.faces]
    (tmp_path / "box.obj").write_text("\n".join(lines))
    places = (("a", (0.0, 0.0)), ("b", second))
    cars = [{"path": "box.obj", "class": "car", "instance": name, "position": [x, y, 0],
             "parts": {"Shell": "body"}} for name, (x, y) in places]  # fmt: skip
    site = {"format": "seminspect-site", "version": 1, "ground": {"margin": 4, "z": 0},
            "start": {"position": start}, "meshes": cars}  # fmt: skip
    (tmp_path / "site.yaml").write_text(yaml.safe_dump(site))
    return str(tmp_path / "site.yaml")


def test_check_passes_a_good_site(capsys, tmp_path) -> None:
    code, out, _ = run(capsys, "world", "check", _site(tmp_path, [-4, -3, 0]))
    assert code == 0 and "ready (0 warning(s))" in out and "error" not in out


def test_check_fails_with_every_error_named(capsys, tmp_path) -> None:
    code, out, _ = run(capsys, "world", "check", _site(tmp_path, [0, 0, 0], second=(1.0, 0.5)))
    text = " ".join(out.split())
    assert code == 1 and "2 error(s), 0 warning(s)" in text
    assert "error: a and b overlap" in text and "inside an obstacle" in text


def test_check_lists_every_missing_mesh(capsys, tmp_path) -> None:
    site = _site(tmp_path, [-4, -3, 0])
    (tmp_path / "box.obj").unlink()
    code, out, _ = run(capsys, "world", "check", site)
    text = " ".join(out.split())
    assert code == 1 and text.count("no such file") == 2 and "meshes[1].path" in text


def test_an_octomap_is_not_shown_as_a_world(capsys, tmp_path) -> None:
    octomap = tmp_path / "geb079.bt"
    octomap.write_bytes(b"# Octomap OcTree binary file\n")
    code, _, err = run(capsys, "world", "show", str(octomap), "-o", str(tmp_path / "m.png"))
    assert code == 1 and err.count("\n") == 1
    assert "an OctoMap is a map, not a world" in err and "exactly one mesh" not in err
