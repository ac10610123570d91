"""Sweeps of any program: the program's run and outcome make each row, groups get mean and
spread, the tables are written, exclusive tasks run alone and a failure is one row; a stopped
sweep keeps its finished rows, marks the others interrupted and writes partial tables."""

import csv
import json
import signal
from pathlib import Path

import pytest

from seminspect.core.interrupts import Interrupted
from seminspect.runs.sweep import (
    CANCEL_GRACE_S,
    Outcome,
    SweepInterrupted,
    SweepProgram,
    SweepRow,
    SweepTask,
    _gather,
    remove_tables,
    run_locally,
    run_on_ray,
    summarise,
    sweep_tables,
)

COLUMNS = (("rmse_xy_m", "m"), ("sim_s", "s"))


def _run(task: SweepTask) -> bool:
    if task.name == "b":
        raise ValueError(f"no run for {task.name}")
    return True


def _outcome(run_dir: Path) -> Outcome:
    return "completed", {"rmse_xy_m": 0.25, "sim_s": 100.0}


PROGRAM = SweepProgram(run=_run, outcome=_outcome, columns=COLUMNS)


def _row(name: str, group: str, seed: int, rmse: float | None, state="completed") -> SweepRow:
    figures = dict.fromkeys((c for c, _ in COLUMNS), None) | {"rmse_xy_m": rmse}
    return SweepRow(name, group, seed, state, figures=figures)


def test_groups_get_the_mean_and_spread_of_their_finished_runs(tmp_path) -> None:
    rows = [
        _row("a0", "a", 0, 0.1), _row("a1", "a", 1, 0.2), _row("a2", "a", 2, 0.3),
        _row("a3", "a", 3, None, state="failed"), _row("b0", "b", 0, 0.5),
    ]  # fmt: skip
    a, b = summarise(rows, COLUMNS)
    assert (a.group, a.runs, a.failed) == ("a", 4, 1)
    assert a.mean["rmse_xy_m"] == pytest.approx(0.2)
    assert a.spread["rmse_xy_m"] == pytest.approx(0.1)  # sample standard deviation of 0.1-0.3
    assert b.mean["rmse_xy_m"] == 0.5 and b.spread["rmse_xy_m"] is None
    written = sweep_tables(rows, tmp_path, COLUMNS)
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
                def remote(task: SweepTask, _program: SweepProgram) -> int:
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
        return SweepRow(task.name, task.group, task.seed, "completed")


def _tasks(names: str, exclusive: bool) -> list[SweepTask]:
    return [SweepTask(n, "g", {}, f"/nowhere/{n}", seed, exclusive) for seed, n in enumerate(names)]


def test_exclusive_tasks_run_first_and_never_beside_each_other() -> None:
    free, alone = _tasks("abc", exclusive=False), _tasks("xy", exclusive=True)
    ray = _FakeRay()
    rows = _gather(ray, free + alone, PROGRAM, None, slots=2)
    assert [row.name for row in rows] == [t.name for t in free + alone]  # in the tasks' order
    assert ray.started[0] == alone[0].name  # the exclusive chain never waits behind the others
    alone_names = {t.name for t in alone}
    assert all(len(set(names) & alone_names) <= 1 for names in ray.in_flight)
    assert max(len(names) for names in ray.in_flight) == 2  # both slots are used


def test_a_task_whose_run_fails_is_a_failed_row_naming_the_error(tmp_path) -> None:
    (done,) = _tasks("d", exclusive=False)
    (broken,) = _tasks("b", exclusive=False)
    rows = run_locally([done, broken], PROGRAM)
    assert [(r.state, r.reused, r.figures) for r in rows[:1]] == [
        ("completed", True, {"rmse_xy_m": 0.25, "sim_s": 100.0})
    ]
    assert rows[1].state == "failed" and rows[1].error.startswith("ValueError: no run for b (")


def _stop_at(name: str, stop: KeyboardInterrupt):
    """A program whose run of task ``name`` is cut short by ``stop``."""

    def run(task: SweepTask) -> bool:
        if task.name == name:
            raise stop
        return True

    return SweepProgram(run=run, outcome=_outcome, columns=COLUMNS)


@pytest.mark.parametrize(
    ("stop", "signum"),
    [(KeyboardInterrupt(), signal.SIGINT), (Interrupted(signal.SIGTERM), signal.SIGTERM)],
)
def test_a_stopped_local_sweep_keeps_its_finished_rows(stop, signum) -> None:
    tasks = _tasks("abc", exclusive=False)
    with pytest.raises(SweepInterrupted) as raised:
        run_locally(tasks, _stop_at("b", stop))
    assert raised.value.signum == signum and raised.value.exit_code == 128 + signum
    assert [(r.name, r.state) for r in raised.value.rows] == [
        ("a", "completed"), ("b", "interrupted"), ("c", "interrupted"),
    ]  # fmt: skip
    assert raised.value.rows[2].error == f"not finished: {Interrupted(signum).describe()}"


def test_a_stopped_sweeps_tables_are_marked_partial(tmp_path) -> None:
    rows = [_row("a0", "a", 0, 0.1), _row("a1", "a", 1, 0.3)]
    rows.append(SweepRow("a2", "a", 2, "interrupted", error="not finished: stopped by SIGTERM"))
    csv_file, json_file, md_file = sweep_tables(rows, tmp_path, COLUMNS, "stopped by SIGTERM")
    document = json.loads(json_file.read_text())
    assert document["partial"] is True and document["stopped"] == "stopped by SIGTERM"
    (group,) = document["groups"]
    assert (group["runs"], group["failed"]) == (2, 0)  # a run that never ran is in no group
    assert group["mean"]["rmse_xy_m"] == pytest.approx(0.2)
    assert md_file.read_text().startswith("**Partial table**: the sweep was stopped by SIGTERM;")
    assert "2 of 3 runs finished" in md_file.read_text()
    table = list(csv.DictReader(csv_file.open()))
    assert table[2]["state"] == "interrupted" and "SIGTERM" in table[2]["error"]
    # a complete sweep's tables say nothing of it
    sweep_tables(rows[:2], tmp_path, COLUMNS)
    assert "partial" not in json.loads(json_file.read_text())
    assert "Partial" not in md_file.read_text()


def test_an_earlier_sweeps_tables_are_removed(tmp_path) -> None:
    written = sweep_tables([_row("a0", "a", 0, 0.1)], tmp_path, COLUMNS)
    (tmp_path / "a0").mkdir()
    remove_tables(tmp_path)
    assert not any(path.exists() for path in written) and (tmp_path / "a0").is_dir()


class _StoppedRay(_FakeRay):
    """A Ray whose first wait is cut short by Ctrl-C; the tasks ``ended`` had already ended,
    and of the others the first still ends within the grace."""

    def __init__(self, ended: frozenset[int] = frozenset()) -> None:
        super().__init__()
        self.ended = ended
        self.cancelled: list[int] = []
        self.grace: float | None = None

    def wait(self, refs, num_returns, timeout=None):
        if timeout is None:  # the sweep's own wait for the next row
            raise KeyboardInterrupt
        if timeout == 0:  # what has ended by now
            return [r for r in refs if r in self.ended], [r for r in refs if r not in self.ended]
        self.grace = timeout
        done = sorted(self.ended | {min(set(refs) - self.ended)})
        return done, [r for r in refs if r not in done]

    def cancel(self, ref: int) -> None:
        self.cancelled.append(ref)


def test_a_stopped_ray_sweep_cancels_its_tasks_and_keeps_those_that_ended() -> None:
    ray = _StoppedRay()
    with pytest.raises(SweepInterrupted) as raised:
        _gather(ray, _tasks("abc", exclusive=False), PROGRAM, None, slots=2)
    assert sorted(ray.cancelled) == [0, 1] and ray.grace == CANCEL_GRACE_S
    assert [r.state for r in raised.value.rows] == ["completed", "interrupted", "interrupted"]
    assert raised.value.signum == signal.SIGINT


def test_a_task_that_ended_before_the_stop_is_not_cancelled() -> None:
    ray = _StoppedRay(ended=frozenset({1}))
    with pytest.raises(SweepInterrupted) as raised:
        _gather(ray, _tasks("abc", exclusive=False), PROGRAM, None, slots=2)
    assert ray.cancelled == [0]  # cancelling 1 as its reply arrives can abort Ray's driver
    assert [r.state for r in raised.value.rows] == ["completed", "completed", "interrupted"]


def test_ray_init_does_not_keep_its_own_stop_handlers(monkeypatch) -> None:
    class InitRay(_FakeRay):
        def is_initialized(self) -> bool:
            return False

        def init(self, **_options) -> None:  # Ray's: exits 1, and its native one dumps stacks
            signal.signal(signal.SIGTERM, signal.SIG_DFL)

        def cluster_resources(self) -> dict[str, float]:
            return {"CPU": 1.0}

        def shutdown(self) -> None:
            pass

    def ours(signum, frame) -> None:
        raise AssertionError("not called")

    monkeypatch.setattr("seminspect.runs.sweep._ray", InitRay)
    previous = signal.signal(signal.SIGTERM, ours)
    try:
        run_on_ray(_tasks("a", exclusive=False), PROGRAM, workers=1)
        assert signal.getsignal(signal.SIGTERM) is ours
    finally:
        signal.signal(signal.SIGTERM, previous)
