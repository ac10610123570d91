import json

import pytest

from cli_runner import run
from seminspect.cli.sweep import parse_seeds, parse_settings
from seminspect.core.errors import InvalidInputError


def test_seeds_and_settings_flags() -> None:
    assert parse_seeds("0-2,5") == [0, 1, 2, 5]
    assert parse_settings(["planner=hierarchical,volumetric", "time_budget_s=30"]) == {
        "planner": ["hierarchical", "volumetric"],
        "time_budget_s": [30],
    }
    for bad in ("3-1", "x", ","):
        with pytest.raises(InvalidInputError, match="--seeds"):
            parse_seeds(bad)
    with pytest.raises(InvalidInputError, match="--set"):
        parse_settings(["planner"])


def test_a_grid_and_grid_flags_do_not_mix(capsys, tmp_path) -> None:
    grid = tmp_path / "grid.yaml"
    grid.write_text("worlds: [campus]\n")
    code, _, err = run(capsys, "sweep", "--grid", str(grid), "--world", "city")
    assert code == 1 and "either --grid" in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_a_sweep_on_local_ray_writes_the_table_and_survives_a_failure(capsys, tmp_path) -> None:
    pytest.importorskip("ray", reason="the 'sweep' extra (ray) is not installed")
    out = tmp_path / "sweep"
    out.mkdir()
    (out / "subterranean-seed1-time_budget_s=20").write_text("in the way")  # seed 1 must fail
    code, text, err = run(
        capsys, "sweep", "--world", "subterranean", "--seeds", "0-2", "--set",
        "time_budget_s=20", "--workers", "2", "--out", str(out),
    )  # fmt: skip
    assert code == 1 and "1 of 3 missions failed" in err and "not a run directory" in err
    document = json.loads((out / "sweep.json").read_text())
    states = [r["state"] for r in document["runs"]]
    assert states == ["completed", "failed", "completed"]
    assert (out / "subterranean-seed2-time_budget_s=20" / "metrics.json").is_file()
    (group,) = document["groups"]
    assert (group["runs"], group["failed"]) == (3, 1)
    assert "subterranean time_budget_s=20" in text and "Every run" in text
    # a second sweep reuses the finished runs instead of flying them again
    code, _, _ = run(
        capsys, "sweep", "--world", "subterranean", "--seeds", "0", "--set", "time_budget_s=20",
        "--workers", "1", "--out", str(out),
    )  # fmt: skip
    again = json.loads((out / "sweep.json").read_text())["runs"]
    assert code == 0 and again[0]["reused"] is True


def test_a_setting_given_twice_is_refused_naming_it() -> None:
    with pytest.raises(InvalidInputError, match="--set gives time_budget_s twice"):
        parse_settings(["time_budget_s=30", "planner=volumetric", "time_budget_s=60"])


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ("time_budget_s=1,1.0", "repeats a mission"),  # one mission, flown twice
        ("time_budget_s=true", "time_budget_s takes no true/false"),  # would pass as 1 s
    ],
)
def test_values_that_pass_for_others_are_one_line(capsys, tmp_path, values, message) -> None:
    out = tmp_path / "sweep"
    code, _, err = run(capsys, "sweep", "--world", "campus", "--set", values, "--out", str(out))
    assert code == 1 and message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()  # refused before anything ran
