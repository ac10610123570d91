import json
from pathlib import Path

import pytest

from cli_runner import run


@pytest.mark.slow
def test_mission_runs_and_says_where_the_results_are(capsys, tmp_path: Path) -> None:
    out = tmp_path / "tunnel"
    code, text, _ = run(
        capsys, "mission", "--world", "subterranean", "--out", str(out), "--query", "Visit car-0"
    )
    assert code == 0
    assert "completed" in text and str(out) in text and "query 'Visit car-0': reached" in text
    assert f"results: {out}  (report.html, summary.md, graph.json, 3 pictures (*.png))" in text
    for picture in ("trajectory.png", "graph.png", "utility.png"):
        assert (out / picture).read_bytes()[:4] == b"\x89PNG"
    assert "plotly" in (out / "report.html").read_text(encoding="utf-8")


@pytest.mark.slow
def test_the_frontier_explorer_runs_from_the_command_line(capsys, tmp_path: Path) -> None:
    out = tmp_path / "explorer"
    code, text, _ = run(
        capsys, "mission", "--world", "city", "--scenario", "small", "--planner", "frontier",
        "--budget", "60", "--no-pictures", "--out", str(out),
    )  # fmt: skip
    assert code == 0 and "completed" in text and "inspected 0%" in text
    # the results line names only what was written: --no-pictures draws neither PNG nor page
    assert f"results: {out}  (summary.md, graph.json, no pictures)" in text
    assert '"planner": "frontier"' in (out / "config.json").read_text(encoding="utf-8")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("mission", "--world", "atlantis"), "unknown world 'atlantis'"),
        (("mission", "--preset", "urban"), "preset"),
        (("mission", "--seed", "-3"), "--seed"),
        (("mission", "--planner", "gbplanner"), "--planner"),
        (("mission", "--carving-spacing", "9"), "--carving-spacing"),
        (("mission", "--robots", "explorer,pilot"), "should be 'explorer' or 'inspector'"),
        (("mission", "--robots", "inspector"), "a team is one explorer and one inspector"),
        (
            ("mission", "--robots", "explorer,inspector", "--planner", "frontier"),
            "a team inspects",
        ),
    ],
)
def test_bad_mission_settings_exit_non_zero_with_one_line(capsys, tmp_path, args, message) -> None:
    code, _, err = run(capsys, *args, "--out", str(tmp_path / "run"))
    assert code != 0 and message in err and "Traceback" not in err
    assert err.strip().count("\n") == 0  # one line


def test_resume_refuses_mixed_settings_and_finished_runs(capsys, tmp_path: Path) -> None:
    from seminspect.missions.xflie.config import make_config, resolve
    from seminspect.runs.directory import RunDirectory

    config = resolve(make_config({"world": "subterranean"})).model_dump(mode="json")
    with RunDirectory(tmp_path / "run").claimed(config) as stored:
        stored.finish("completed")
    code, _, err = run(capsys, "mission", "--resume", str(tmp_path / "run"), "--seed", "2")
    assert code == 1 and "drop --seed" in err
    code, _, err = run(capsys, "mission", "--resume", str(tmp_path / "run"))
    assert code == 1 and "completed run; nothing to resume" in err
    code, _, err = run(capsys, "mission", "--resume", str(tmp_path))
    assert code == 1 and "not a run directory" in err


def test_an_existing_bag_is_refused_before_the_mission(capsys, tmp_path) -> None:
    (tmp_path / "taken").mkdir()
    code, _, err = run(
        capsys, "mission", "--bag", str(tmp_path / "taken"), "--out", str(tmp_path / "run")
    )
    assert code == 1 and "exists; choose a new bag name" in err
    assert not (tmp_path / "run").exists()


def test_features_choose_the_parts_recorded_and_the_rest_are_named(capsys, tmp_path) -> None:
    from seminspect.worlds import WorldBuilder, save_world
    from seminspect.worlds.shapes import box

    builder = WorldBuilder("odd")
    builder.add_ground((-5.0, -5.0), (5.0, 5.0))
    parts = ("body", "mirror", "windows")
    builder.add_object([box((i, 0, 0), (i + 1, 1, 1), p) for i, p in enumerate(parts)], "car")
    save_world(
        builder.build([(-5.0, -5.0, 0.0), (5.0, 5.0, 3.0)], (-4.0, 0.0, 0.0)), tmp_path / "w"
    )
    code, _, err = run(
        capsys, "mission", "--world", str(tmp_path / "w"), "--features", "windows",
        "--budget", "30", "--no-pictures", "--out", str(tmp_path / "run"),
    )  # fmt: skip
    assert code == 0, err
    assert "ignored: mirror; add them to 'seminspect mission --features'" in err
    config = json.loads((tmp_path / "run" / "config.json").read_text(encoding="utf-8"))
    assert config["config"]["feature_labels"] == ["windows"]
    code, _, err = run(capsys, "mission", "--features", "a/b", "--out", str(tmp_path / "bad"))
    assert code != 0 and "invalid semantic label 'a/b'" in err and "Traceback" not in err
