"""A run on a full disk: its directory says it failed and which file could not be written (or
the error says the status could not be), and a new run takes the directory over."""

import threading
from pathlib import Path

import pytest

from full_disk import fill_disk
from seminspect.core.errors import SeminspectError
from seminspect.core.io import atomic_write_text
from seminspect.runs import directory
from seminspect.runs.conduct import RunEnd, conduct_run
from seminspect.runs.directory import METRICS_FILE, RunDirectory, RunLayout
from seminspect.runs.lock import LOCK_FILE
from seminspect.runs.status import read_run_status

CONFIG = {"world": "subterranean", "seed": 0}
LAYOUT = RunLayout(files=frozenset({"result.json"}), outputs=("result.json", METRICS_FILE))


def _conduct(root: Path) -> RunEnd:
    """A fake program's run: its work, then its result and metrics."""
    run = RunDirectory(root, LAYOUT)

    def write_outputs(end: RunEnd) -> None:
        atomic_write_text(run.path("result.json"), "[" + "0, " * 1000 + "0]")
        run.write_metrics("test.metrics", {"state": end.state})

    with run.claimed(CONFIG):
        return conduct_run(run, lambda: "done", write_outputs, expected=LAYOUT.outputs, what="run")


def _taken_over(root: Path) -> bool:
    """Whether a new run accepts the directory (as ``mission --out`` does)."""
    with RunDirectory(root, LAYOUT).claimed(CONFIG) as run:
        run.finish("completed")
    return read_run_status(root).state == "completed"


def test_a_file_the_full_disk_refuses_is_named_by_the_status(tmp_path, monkeypatch) -> None:
    fill_disk(monkeypatch, "result.json")
    with pytest.raises(SeminspectError, match=r"no space left on device, writing result\.json"):
        _conduct(tmp_path / "run")
    status = read_run_status(tmp_path / "run")
    assert status.state == "failed"
    assert "no space left on device, writing result.json" in status.reason
    assert "not written: result.json, metrics.json" in status.reason
    monkeypatch.undo()
    assert _taken_over(tmp_path / "run")


def test_a_disk_with_no_room_for_a_copy_gets_the_status_rewritten_in_place(
    tmp_path, monkeypatch
) -> None:
    run = RunDirectory(tmp_path / "run", LAYOUT)
    with pytest.raises(SeminspectError, match=r"writing result\.json"), run.claimed(CONFIG):
        fill_disk(monkeypatch)  # full from here on: status.json's own blocks are all there is

        def write_outputs(end: RunEnd) -> None:
            atomic_write_text(run.path("result.json"), "[]")

        conduct_run(run, lambda: "done", write_outputs, expected=LAYOUT.outputs, what="run")
    status = read_run_status(run.root)
    assert status.state == "failed" and "writing result.json" in status.reason
    assert sorted(p.name for p in run.root.iterdir()) == ["config.json", "status.json"]
    monkeypatch.undo()
    assert _taken_over(run.root)


def test_a_status_the_full_disk_refuses_is_named_with_its_directory(tmp_path, monkeypatch) -> None:
    run = RunDirectory(tmp_path / "run", LAYOUT)
    with pytest.raises(SeminspectError) as raised, run.claimed(CONFIG):
        fill_disk(monkeypatch, in_place=True)
        conduct_run(run, lambda: "done", lambda end: None, expected=(), what="run")
    message = str(raised.value)
    assert message.startswith(f"{run.root}: could not record how the run ended (completed")
    assert "no space left on device, writing status.json" in message
    assert not (run.root / LOCK_FILE).exists()  # the directory is free for the next run
    monkeypatch.undo()
    assert _taken_over(run.root)


def test_a_configuration_the_full_disk_refuses_is_recorded_as_failed(tmp_path, monkeypatch) -> None:
    fill_disk(monkeypatch, "config.json")
    with pytest.raises(OSError, match="No space left") as raised:
        _conduct(tmp_path / "run")
    assert raised.value.filename == str(tmp_path / "run" / "config.json")
    status = read_run_status(tmp_path / "run")
    assert (
        status.state == "failed" and status.reason == "no space left on device, writing config.json"
    )


def test_a_heartbeat_lost_to_a_full_disk_does_not_end_the_run(tmp_path, monkeypatch) -> None:
    monkeypatch.setattr(directory, "HEARTBEAT_S", 0.01)
    crashes: list[threading.ExceptHookArgs] = []
    monkeypatch.setattr(threading, "excepthook", crashes.append)
    with RunDirectory(tmp_path / "run", LAYOUT).claimed(CONFIG) as run:
        fill_disk(monkeypatch, "status.json")
        threading.Event().wait(0.1)  # heartbeats come and fail
        monkeypatch.undo()
        run.finish("completed")
    assert not crashes and read_run_status(run.root).state == "completed"
