import json
import socket
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


#: The figures of metrics.json that measure the computer, not the mission.
WALL_CLOCK = {
    "avg_planning_time_ms", "cpu_load_pct", "planning_load_pct", "wall_time_s",
    "real_time_factor", "local_planning_ms_mean", "planning_wall_s", "wall_time_by_category_s",
}  # fmt: skip


def _mission_figures(document):
    if isinstance(document, dict):
        return {k: _mission_figures(v) for k, v in document.items() if k not in WALL_CLOCK}
    return document


def _files(run_dir: Path) -> list[Path]:
    return sorted(p.relative_to(run_dir) for p in run_dir.rglob("*") if p.is_file())


@pytest.mark.slow
def test_record_mcap_adds_the_recording_and_changes_no_other_output(capsys, tmp_path) -> None:
    pytest.importorskip("rosbags", reason="the 'ros' extra (rosbags) is not installed")
    mission = ("mission", "--world", "subterranean", "--budget", "25", "--no-pictures")
    plain, recorded = tmp_path / "plain", tmp_path / "recorded"
    assert run(capsys, *mission, "--out", str(plain))[0] == 0
    code, text, _ = run(capsys, *mission, "--record-mcap", "--out", str(recorded))
    assert code == 0 and f"MCAP recording: {recorded / 'run.mcap'}" in text
    assert _files(recorded) == sorted([*_files(plain), Path("run.mcap")])
    # status.json and summary.md tell the wall-clock time and the process, which differ anyway
    for name in set(_files(plain)) - {Path("status.json"), Path("summary.md")}:
        if name.name == "metrics.json":
            figures = [json.loads((d / name).read_text()) for d in (plain, recorded)]
            assert _mission_figures(figures[0]) == _mission_figures(figures[1])
        else:
            assert (plain / name).read_bytes() == (recorded / name).read_bytes(), name


@pytest.mark.slow
def test_a_failed_recording_is_one_line_and_leaves_no_file(capsys, tmp_path, monkeypatch) -> None:
    pytest.importorskip("rosbags", reason="the 'ros' extra (rosbags) is not installed")
    from seminspect.core.errors import InvalidInputError

    def unplugged(*args, **kwargs):
        raise InvalidInputError("camera unplugged")

    monkeypatch.setattr("seminspect.missions.xflie.recording.render", unplugged)
    out = tmp_path / "run"
    code, text, err = run(
        capsys, "mission", "--world", "subterranean", "--budget", "25", "--no-pictures",
        "--record-mcap", "--out", str(out),
    )  # fmt: skip
    assert code == 1 and "completed" in text and f"results: {out}" in text
    assert err.strip() == "error: camera unplugged"
    assert not [p for p in out.iterdir() if "mcap" in p.name]


def test_view_on_a_port_in_use_is_one_line_before_the_mission(capsys, tmp_path) -> None:
    out = tmp_path / "run"
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        code, _, err = run(capsys, "mission", "--view", "--view-port", str(port), "--out", str(out))
    assert code != 0
    assert f"cannot serve the live view on 127.0.0.1:{port}" in err and "Traceback" not in err
    assert not out.exists()


def test_a_team_cannot_be_watched(capsys, tmp_path) -> None:
    out = tmp_path / "team"
    code, _, err = run(
        capsys, "mission", "--robots", "explorer,inspector", "--view", "--view-port", "0",
        "--out", str(out),
    )  # fmt: skip
    assert code != 0 and "a team cannot be watched yet" in err
    assert not out.exists()


@pytest.mark.slow
def test_view_prints_its_address_and_changes_no_output(capsys, tmp_path, monkeypatch) -> None:
    monkeypatch.setattr("seminspect.cli._common.VIEW_WAIT_S", 0.5)  # no browser comes
    args = ("--world", "campus", "--scenario", "small", "--budget", "60", "--no-pictures")
    code, _, _ = run(capsys, "mission", *args, "--out", str(tmp_path / "plain"))
    assert code == 0
    code, text, err = run(
        capsys, "mission", *args, "--view", "--view-port", "0", "--out", str(tmp_path / "seen")
    )
    assert code == 0 and "completed" in text
    assert "live view at http://127.0.0.1:" in err
    for name in ("graph.json", "trajectory.csv", "events.jsonl"):
        assert (tmp_path / "seen" / name).read_bytes() == (tmp_path / "plain" / name).read_bytes()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--detector", "model.pt"), "expected 'truth' or an ONNX model file"),
        (("--detector", "model.onnx"), "model.onnx"),
        (("--class-map", "classes.json"), "--class-map goes with an ONNX --detector"),
        (("--detector", "missing.onnx", "--class-map", "classes.json"), "missing.onnx"),
    ],
)
def test_a_detector_that_cannot_be_used_is_one_line_before_the_mission(
    capsys, tmp_path, args, message
) -> None:
    (tmp_path / "classes.json").write_text('{"instance": {"0": "car"}}', encoding="utf-8")
    out = tmp_path / "run"
    resolved = [str(tmp_path / a) if a.endswith((".json", ".onnx")) else a for a in args]
    code, _, err = run(capsys, "mission", *resolved, "--out", str(out))
    assert code != 0 and message in err and "Traceback" not in err
    assert err.strip().count("\n") == 0
    assert not out.exists()
