"""``seminspect routine``: map, inspect with a recorded prior, and one-line errors."""

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
