"""Sweeps of missions: the grid expands into validated tasks, finished runs are reused with the
figures of their typed metrics, failures are rows, and wall-time-charging missions run alone;
values that pass for others (true for 1, 1.0 for 1) are refused, and a directory a killed run
left is taken over."""

import shutil
from pathlib import Path

import pytest

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.missions.xflie.layout import read_run_metrics
from seminspect.missions.xflie.sweep import (
    COLUMNS,
    MISSIONS,
    SweepSpec,
    expand,
    load_spec,
    metric_figures,
)
from seminspect.runs.lock import LOCK_FILE, RunDirectoryWarning, RunLock
from seminspect.runs.sweep import run_locally


def test_the_grid_expands_into_one_validated_task_per_mission(tmp_path, monkeypatch) -> None:
    spec = SweepSpec(
        worlds=["city", "campus"], scenarios=["small"], seeds=[0, 1],
        settings={"planner": ["hierarchical", "volumetric"]},
    )  # fmt: skip
    tasks = expand(spec, tmp_path)
    assert len(tasks) == 8 and len({t.name for t in tasks}) == 8
    first = tasks[0]
    assert first.name == "city-small-seed0-planner=hierarchical"
    assert first.group == "city small planner=hierarchical"
    assert first.config["time_budget_s"] is not None  # resolved, as reusable_run compares it
    assert {t.run_dir for t in tasks} == {str(tmp_path / t.name) for t in tasks}
    monkeypatch.chdir(tmp_path)  # Ray workers may run elsewhere: run directories are absolute
    assert expand(spec, "rel")[0].run_dir == str(tmp_path.resolve() / "rel" / first.name)
    with pytest.raises(InvalidInputError, match="planner"):
        expand(SweepSpec(worlds=["city"], settings={"planner": ["teleport"]}), tmp_path)
    with pytest.raises(InvalidInputError, match="repeats a mission"):
        expand(SweepSpec(worlds=["city"], seeds=[1, 1]), tmp_path)


def test_a_yaml_grid_is_read_and_bad_ones_are_one_line(tmp_path) -> None:
    grid = tmp_path / "grid.yaml"
    grid.write_text("worlds: [campus]\nseeds: [0, 1, 2]\nsettings:\n  noise: [ideal]\n")
    spec = load_spec(grid)
    assert spec.seeds == [0, 1, 2] and spec.settings == {"noise": ["ideal"]}
    grid.write_text("worlds: [campus]\ncolour: blue\n")
    with pytest.raises(FileFormatError, match="colour"):
        load_spec(grid)
    grid.write_text("worlds: [campus\n")
    with pytest.raises(FileFormatError, match="malformed YAML"):
        load_spec(grid)


def test_a_finished_run_is_reused_and_a_broken_task_is_a_failed_row(
    small_mission_dir, tmp_path
) -> None:
    spec = SweepSpec(worlds=["campus"], scenarios=["small"], seeds=[0, 1])
    reused_task, broken_task = expand(spec, tmp_path)
    shutil.copytree(small_mission_dir, reused_task.run_dir)
    (tmp_path / broken_task.name).write_text("not a directory")
    seen = []
    rows = run_locally([reused_task, broken_task], MISSIONS, on_row=seen.append)
    assert seen == rows
    reused, broken = rows
    assert reused.reused and reused.state == "completed"
    assert reused.figures == metric_figures(read_run_metrics(small_mission_dir))
    assert reused.figures["inspected_pct"] is not None
    assert broken.state == "failed" and "not a run directory" in broken.error


def test_every_column_is_a_figure_of_the_typed_metrics(small_mission_dir) -> None:
    metrics = read_run_metrics(small_mission_dir)
    figures = metric_figures(metrics)
    assert [name for name, _ in MISSIONS.columns] == [name for name, _, _ in COLUMNS]
    assert figures["target_nodes"] == metrics.table3.target[0]
    assert figures["sim_s"] == metrics.mission.sim_time_s
    assert all(value is not None for name, value in figures.items() if name != "avg_planning_ms")


def test_missions_that_charge_wall_time_must_run_alone(tmp_path) -> None:
    free = expand(SweepSpec(worlds=["campus"], seeds=[0, 1]), tmp_path)
    charged = expand(
        SweepSpec(worlds=["city"], seeds=[0], settings={"charge_planning_time": [True]}), tmp_path
    )
    assert [t.exclusive for t in free + charged] == [False, False, True]
    assert [t.seed for t in free + charged] == [0, 1, 0]


@pytest.mark.parametrize(
    ("grid", "key"),
    [
        ("seeds: [true]\n", "seeds.0"),
        ("settings:\n  time_budget_s: [30, true]\n", "time_budget_s"),
        ("settings:\n  map_resolution: [true]\n", "map_resolution"),
    ],
)
def test_a_true_or_false_for_a_number_is_refused_naming_the_file(tmp_path, grid, key) -> None:
    path = tmp_path / "grid.yaml"
    path.write_text("worlds: [campus]\n" + grid)
    with pytest.raises(FileFormatError, match=key) as raised:
        load_spec(path)
    assert str(raised.value).startswith(f"{path}: ")
    path.write_text("worlds: [campus]\nsettings:\n  charge_planning_time: [true, false]\n")
    assert load_spec(path).settings == {"charge_planning_time": [True, False]}  # a switch


def test_values_that_make_one_mission_twice_are_refused(tmp_path) -> None:
    spec = SweepSpec(worlds=["campus"], settings={"time_budget_s": [1, 1.0]})
    with pytest.raises(InvalidInputError, match=r"repeats a mission \(campus-.*=1 and .*=1\.0\)"):
        expand(spec, tmp_path)


def test_a_directory_a_killed_run_left_with_its_lock_is_taken_over(tmp_path) -> None:
    (task,) = expand(SweepSpec(worlds=["subterranean"], settings={"time_budget_s": [5]}), tmp_path)
    run_dir = Path(task.run_dir)
    run_dir.mkdir()
    (run_dir / LOCK_FILE).write_text("999999999 elsewhere\n")  # no process holds it
    with pytest.warns(RunDirectoryWarning, match="lock of process 999999999"):
        (row,) = run_locally([task], MISSIONS)
    assert (row.state, row.error) == ("completed", "")
    assert not (run_dir / LOCK_FILE).exists()


def test_a_run_directory_in_use_is_neither_deleted_nor_run(tmp_path) -> None:
    (task,) = expand(SweepSpec(worlds=["subterranean"]), tmp_path)
    run_dir = Path(task.run_dir)
    run_dir.mkdir()
    (run_dir / "status.json").write_text('{"state": "running"}')
    lock = RunLock.acquire(run_dir / LOCK_FILE)  # a live writer: this process
    try:
        (row,) = run_locally([task], MISSIONS)
        assert row.state == "failed" and "in use by another run" in row.error
        assert (run_dir / "status.json").read_text() == '{"state": "running"}'
    finally:
        lock.release()
