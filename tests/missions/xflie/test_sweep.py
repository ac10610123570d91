"""Sweeps: the grid expands into validated tasks, finished runs are reused, failures are rows."""

import csv
import shutil

import pytest

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.missions.xflie.sweep import (
    COLUMNS,
    SweepRow,
    SweepSpec,
    SweepTask,
    _gather,
    charges_wall_time,
    expand,
    load_spec,
    metric_figures,
    run_locally,
    summarise,
    sweep_tables,
)
from seminspect.runs.directory import read_metrics_document


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
    rows = run_locally([reused_task, broken_task], on_row=seen.append)
    assert seen == rows
    reused, broken = rows
    assert reused.reused and reused.state == "completed"
    assert reused.figures == metric_figures(read_metrics_document(small_mission_dir))
    assert reused.figures["inspected_pct"] is not None
    assert broken.state == "failed" and "not a run directory" in broken.error


def _row(name: str, group: str, seed: int, rmse: float | None, state="completed") -> SweepRow:
    figures = dict.fromkeys((c for c, _, _ in COLUMNS), None) | {"rmse_xy_m": rmse}
    return SweepRow(name, group, seed, state, figures=figures)


def test_groups_get_the_mean_and_spread_of_their_finished_runs(tmp_path) -> None:
    rows = [
        _row("a0", "a", 0, 0.1), _row("a1", "a", 1, 0.2), _row("a2", "a", 2, 0.3),
        _row("a3", "a", 3, None, state="failed"), _row("b0", "b", 0, 0.5),
    ]  # fmt: skip
    a, b = summarise(rows)
    assert (a.group, a.runs, a.failed) == ("a", 4, 1)
    assert a.mean["rmse_xy_m"] == pytest.approx(0.2)
    assert a.spread["rmse_xy_m"] == pytest.approx(0.1)  # sample standard deviation of 0.1-0.3
    assert b.mean["rmse_xy_m"] == 0.5 and b.spread["rmse_xy_m"] is None
    written = sweep_tables(rows, tmp_path)
    assert [p.name for p in written] == ["sweep.csv", "sweep.json", "sweep.md"]
    table = list(csv.DictReader(written[0].open()))
    assert [r["run"] for r in table] == ["a0", "a1", "a2", "a3", "b0"]
    assert table[3]["state"] == "failed" and table[3]["rmse_xy_m"] == ""
    markdown = written[2].read_text()
    assert "| a | 4 | 1 |" in markdown and "0.2 ± 0.1" in markdown


class _FakeRay:
    """Enough of Ray for the scheduler: tasks finish in the order they were started, and the
    tasks in flight are recorded at every start."""

    def __init__(self) -> None:
        self.started: list[str] = []
        self.in_flight: list[list[str]] = []
        self._pending: list[tuple[int, SweepTask]] = []

    def remote(self, **_options):
        def wrap(function):
            fake = self

            class Remote:
                @staticmethod
                def remote(task: SweepTask) -> int:
                    fake._pending.append((len(fake.started), task))
                    fake.started.append(task.name)
                    fake.in_flight.append([t.name for _, t in fake._pending])
                    return len(fake.started) - 1

            return Remote

        return wrap

    def wait(self, refs, num_returns):
        assert num_returns == 1
        return [min(refs)], []

    def get(self, ref: int) -> SweepRow:
        ((_, task),) = [entry for entry in self._pending if entry[0] == ref]
        self._pending.remove((ref, task))
        return SweepRow(task.name, task.group, int(task.config["seed"]), "completed")


def test_missions_that_charge_wall_time_run_first_and_never_beside_each_other(tmp_path) -> None:
    free = expand(SweepSpec(worlds=["campus"], seeds=[0, 1, 2]), tmp_path)
    charged = expand(
        SweepSpec(worlds=["city"], seeds=[0, 1], settings={"charge_planning_time": [True]}),
        tmp_path,
    )
    assert [charges_wall_time(t) for t in free + charged] == [False] * 3 + [True] * 2
    ray = _FakeRay()
    rows = _gather(ray, free + charged, None, slots=2)
    assert [row.name for row in rows] == [t.name for t in free + charged]  # in the tasks' order
    assert ray.started[0] == charged[0].name  # the charged chain never waits behind the others
    charged_names = {t.name for t in charged}
    assert all(len(set(names) & charged_names) <= 1 for names in ray.in_flight)
    assert max(len(names) for names in ray.in_flight) == 2  # both slots are used
