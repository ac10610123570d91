"""``seminspect routine``: map, inspect with a recorded prior, and one-line errors."""

import socket

import pytest

from cli_runner import run
from seminspect.core.io import read_versioned_json


def test_map_then_inspect_with_the_recorded_prior(capsys, tmp_path):
    prior = tmp_path / "prior" / "map.npz"
    code, out, err = run(
        capsys, "routine", "map", "--scenario", "obstructed", "--length", "12",
        "--out", str(tmp_path / "prior"),
    )  # fmt: skip
    assert code == 0, err
    assert prior.exists() and str(prior) in out.replace("\n", "")
    code, out, err = run(
        capsys, "routine", "inspect", "--scenario", "obstructed", "--length", "12",
        "--prior", str(prior), "--out", str(tmp_path / "run"),
    )  # fmt: skip
    assert code == 0, err
    assert "tasks 2/2" in out and "collisions 0" in out
    assert out.startswith("completed: ")  # styled, not printed as markup
    status = read_versioned_json(tmp_path / "run" / "status.json", "seminspect.run-status", [1])
    assert status["state"] == "completed"
    assert (tmp_path / "run" / "performance.png").exists()
    assert (tmp_path / "run" / "changes.png").exists()
    assert (tmp_path / "run" / "report.html").is_file()
    assert "(report.html, summary.md, metrics.json, 2 pictures (*.png))" in out.replace("\n", "")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--scenario", "sideways"], "unknown routine scenario"),
        (["--world", "city"], "mine drift only"),
        (["--prior", "nothing.bt2"], "prior map"),
        (["--tasks", "absent.yaml"], "no such file"),
    ],
)
def test_bad_input_is_one_line_and_exit_1(capsys, tmp_path, args, message):
    code, _, err = run(capsys, "routine", "inspect", *args, "--out", str(tmp_path / "x"))
    assert code == 1
    assert message in err and "Traceback" not in err
    assert len(err.strip().splitlines()) <= 2  # rich may wrap the one line


def test_a_user_site_from_two_exported_worlds(capsys, tmp_path):
    from seminspect.worlds import save_world
    from seminspect.worlds.routine_sites import face_region, mine_drift_site

    site = mine_drift_site("advancing", 0, 12.0)
    save_world(site.historical, tmp_path / "before")
    save_world(site.current, tmp_path / "after")
    tasks = tmp_path / "tasks.yaml"
    tasks.write_text(f"regions:\n  - name: face\n    vertices: {face_region(12.0).tolist()}\n")
    code, out, err = run(
        capsys, "routine", "inspect", "--historical", str(tmp_path / "before"),
        "--current", str(tmp_path / "after"), "--tasks", str(tasks), "--no-pictures",
        "--out", str(tmp_path / "run"),
    )  # fmt: skip
    assert code == 0, err
    assert "tasks 1/1" in out
    assert not (tmp_path / "run" / "report.html").exists() and "no pictures" in out
    code, _, err = run(
        capsys, "routine", "inspect", "--historical", str(tmp_path / "before"),
        "--out", str(tmp_path / "x"),
    )  # fmt: skip
    assert code == 1 and "go together" in err
    code, _, err = run(
        capsys, "routine", "inspect", "--historical", str(tmp_path / "before"),
        "--current", str(tmp_path / "after"), "--out", str(tmp_path / "y"),
    )  # fmt: skip
    assert code == 1 and "task file" in err


def _room_bt(path, size=(30, 20, 15), resolution=0.2):
    """A closed 6 x 4 x 3 m room as an OctoMap: shell occupied, inside free."""
    import numpy as np

    pyoctomap = pytest.importorskip("pyoctomap")
    tree = pyoctomap.OcTree(resolution)
    for cell in np.ndindex(*size):
        shell = any(c in (0, n - 1) for c, n in zip(cell, size, strict=True))
        tree.updateNode((np.array(cell) + 0.5) * resolution, bool(shell))
    assert tree.writeBinary(str(path))
    return path


def _room_site(folder):
    """The room OctoMap and a task file of one region on its east wall."""
    tasks = folder / "tasks.yaml"
    region = [[5.8, 1.2, 0.8], [5.8, 2.8, 0.8], [5.8, 2.8, 2.0], [5.8, 1.2, 2.0]]
    tasks.write_text(f"regions:\n  - name: east\n    vertices: {region}\n")
    return _room_bt(folder / "room.bt"), tasks


def test_an_octomap_is_the_site_with_world_and_refused_as_the_drifts_prior(capsys, tmp_path):
    bt, tasks = _room_site(tmp_path)
    code, out, err = run(
        capsys, "routine", "inspect", "--world", str(bt), "--tasks", str(tasks),
        "--out", str(tmp_path / "run"),
    )  # fmt: skip
    assert code == 0, err
    assert "tasks 1/1" in out and "collisions 0" in out
    assert (tmp_path / "run" / "prior" / "map.npz").exists()
    assert (tmp_path / "run" / "changes.png").exists()  # drawn from the prior as painted
    code, _, err = run(
        capsys, "routine", "inspect", "--world", str(bt), "--out", str(tmp_path / "x")
    )  # fmt: skip
    assert code == 1 and "no default tasks" in err and "--tasks" in err
    code, _, err = run(
        capsys, "routine", "inspect", "--prior", str(bt), "--out", str(tmp_path / "y")
    )  # fmt: skip
    assert code == 1 and "M_H does not fit the site" in err
    assert f"--world {bt}" in err.replace("\n", "")  # the way to use the map's own site


def test_the_results_line_names_no_pictures_that_were_not_drawn(capsys, tmp_path):
    bt, tasks = _room_site(tmp_path)
    code, out, err = run(
        capsys, "routine", "inspect", "--world", str(bt), "--tasks", str(tasks),
        "--no-pictures", "--out", str(tmp_path / "run"),
    )  # fmt: skip
    assert code == 0, err
    line = next(line for line in out.splitlines() if "results: " in line)
    assert "summary.md, metrics.json" in line and "no pictures" in line and "*.png" not in line


def test_view_with_compare_is_refused_in_one_line_before_any_work(capsys, tmp_path):
    out = tmp_path / "run"
    code, _, err = run(capsys, "routine", "inspect", "--compare", "--view", "--out", str(out))
    assert code == 1 and "--view watches one run: leave out --compare" in err
    assert len(err.strip().splitlines()) <= 2 and not out.exists()


def test_view_on_a_port_in_use_is_one_line_before_the_run(capsys, tmp_path):
    out = tmp_path / "run"
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        code, _, err = run(
            capsys, "routine", "inspect", "--view", "--view-port", str(port), "--out", str(out)
        )
    assert code == 1 and f"cannot serve the live view on 127.0.0.1:{port}" in err
    assert "Traceback" not in err and not out.exists()


@pytest.mark.slow
def test_view_prints_its_address_and_runs_when_nobody_opens_it(capsys, tmp_path, monkeypatch):
    monkeypatch.setattr("seminspect.cli._common.VIEW_WAIT_S", 0.1)
    code, out, err = run(
        capsys, "routine", "inspect", "--scenario", "receding", "--seed", "1", "--length", "12",
        "--no-pictures", "--view", "--view-port", "0", "--out", str(tmp_path / "run"),
    )  # fmt: skip
    assert code == 0, err
    assert "live view at http://127.0.0.1:" in err and out.startswith("completed: ")
