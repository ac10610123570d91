"""Run directories: one writer at a time, no file of an old run beside a new one, a status that
reads a dead writer as dead, and reuse that says why not."""

import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError, SeminspectError
from seminspect.core.provenance import code_version
from seminspect.mapping.voxel import VoxelMap, save_map
from seminspect.runs.conduct import RunEnd, conduct_run
from seminspect.runs.directory import RunDirectory, RunLayout
from seminspect.runs.lock import LOCK_FILE, RunDirectoryInUseError, RunDirectoryWarning
from seminspect.runs.reuse import resumable_config, reusable_run
from seminspect.runs.status import read_run_status
from seminspect.runs.trajectory import load_robot_trajectories, load_trajectory

CONFIG = {"world": "subterranean", "seed": 0}
#: What a program writes besides the common files, as a program declares it.
LAYOUT = RunLayout(
    files=frozenset({"map.npz"}),
    folders={
        "snapshots": re.compile(r"graph-[\d.]+s\.json"),
        "robots": re.compile(r"[a-z]+-trajectory\.csv"),
    },
)


def test_a_claimed_directory_refuses_a_second_writer_naming_the_first(tmp_path) -> None:
    run = RunDirectory(tmp_path / "run")
    with run.claimed(CONFIG):
        status = json.loads(run.path("status.json").read_text())
        assert status["state"] == "running" and status["pid"] == os.getpid()
        second = RunDirectory(tmp_path / "run").claimed(CONFIG)
        with pytest.raises(RunDirectoryInUseError, match=f"process {os.getpid()}"):
            second.__enter__()
        run.finish("completed")
    assert not run.path(LOCK_FILE).exists()
    assert read_run_status(run.root).state == "completed"


def _killed_writer(root: Path) -> int:
    """A process that claims ``root`` and is killed with SIGKILL while running."""
    code = (
        "import sys, time; from seminspect.runs.directory import RunDirectory\n"
        "claim = RunDirectory(sys.argv[1]).claimed({}); claim.__enter__()\n"
        "print('ok', flush=True)\n"
        "time.sleep(60)\n"
    )
    child = subprocess.Popen(
        [sys.executable, "-c", code, str(root)], stdout=subprocess.PIPE, text=True
    )
    assert child.stdout.readline().strip() == "ok"
    child.kill()
    child.wait()
    return child.pid


def test_a_killed_writer_reads_as_dead_and_its_lock_is_taken_over(tmp_path) -> None:
    root = tmp_path / "run"
    pid = _killed_writer(root)
    status = read_run_status(root)
    assert status.recorded == "running" and status.state == "dead" and str(pid) in status.reason
    assert resumable_config(root) == {}
    warned = pytest.warns(RunDirectoryWarning, match=f"lock of process {pid}")
    with warned, RunDirectory(root).claimed(CONFIG) as run:
        run.finish("completed")


def test_a_silent_heartbeat_reads_as_abandoned(tmp_path) -> None:
    run = RunDirectory(tmp_path)
    run.write_status("running", pid=1, host="elsewhere", heartbeat=time.time() - 3600)
    assert read_run_status(tmp_path).state == "abandoned"


def test_a_new_run_clears_the_old_runs_files_but_never_a_strangers(tmp_path) -> None:
    root = tmp_path / "run"
    (root / "snapshots").mkdir(parents=True)
    (root / "snapshots" / "graph-00012.5s.json").write_text("{}")
    (root / "images").mkdir()
    (root / "images" / "car-1-00003.jpg").write_bytes(b"jpg")
    (root / "graph.png").write_bytes(b"png")
    (root / ".metrics.json.k2j4h1.tmp").write_text("{")  # an atomic write cut short
    (root / ".map.npz.bag.partial").mkdir()  # a bag written beside its name, cut short
    (root / ".map.npz.bag.partial" / "metadata.yaml").write_text("")
    with RunDirectory(root, LAYOUT).claimed(CONFIG) as run:
        assert sorted(p.name for p in root.iterdir()) == ["config.json", LOCK_FILE, "status.json"]
        run.finish("completed")
    (root / "notes.txt").write_text("mine")
    (root / "images").mkdir()
    (root / "images" / "holiday.png").write_bytes(b"png")
    with pytest.raises(InvalidInputError, match=r"images, notes\.txt"):
        RunDirectory(root, LAYOUT).claimed(CONFIG).__enter__()  # refused before the claim
    assert (root / "notes.txt").exists() and (root / "config.json").exists()
    assert not (root / LOCK_FILE).exists()


def test_a_teams_trajectories_are_written_per_robot_and_cleared_by_the_next_run(
    tmp_path,
) -> None:
    root = tmp_path / "run"
    rows = {"explorer": [[0.0] * 9, [1.0] * 9], "inspector": [[2.0] * 9]}
    with RunDirectory(root, LAYOUT).claimed(CONFIG) as run:
        run.write_trajectory(rows["explorer"])
        for robot, robot_rows in rows.items():
            run.write_trajectory(robot_rows, robot)
        run.finish("completed")
    trajectories = load_robot_trajectories(root)
    assert {k: v.tolist() for k, v in trajectories.items()} == rows
    assert load_trajectory(root).tolist() == rows["explorer"]
    with RunDirectory(root, LAYOUT).claimed(CONFIG) as run:  # a one-robot run over a team's
        assert load_robot_trajectories(root) == {}
        run.finish("completed")


def test_a_failure_inside_the_claim_is_recorded(tmp_path) -> None:
    run = RunDirectory(tmp_path / "run")
    with pytest.raises(RuntimeError), run.claimed(CONFIG):
        raise RuntimeError("disk on fire")
    status = read_run_status(run.root)
    assert status.state == "failed" and "disk on fire" in status.reason
    with pytest.raises(KeyboardInterrupt), run.claimed(CONFIG):
        raise KeyboardInterrupt
    assert read_run_status(run.root).state == "interrupted"


def _stored_run(root: Path, config: dict, state: str = "completed") -> Path:
    with RunDirectory(root, LAYOUT).claimed(config) as run:
        save_map(root / "map.npz", VoxelMap.empty([0, 0, 0], [1, 1, 1], 0.5))
        run.finish(state)
    return root


def test_reuse_says_why_a_run_cannot_stand_for_a_new_one(tmp_path) -> None:
    same = _stored_run(tmp_path / "same", CONFIG)
    assert reusable_run(same, CONFIG) and not reusable_run(same, CONFIG).reason
    other = reusable_run(same, {**CONFIG, "seed": 3})
    assert not other and "seed: 0 -> 3" in other.reason
    missing = reusable_run(same, CONFIG, needs=("map.npz", "graph.json"))
    assert not missing and missing.reason.endswith("has no graph.json")
    stopped = reusable_run(_stored_run(tmp_path / "stopped", CONFIG, "interrupted"), CONFIG)
    assert not stopped and "interrupted" in stopped.reason
    assert "no readable run" in reusable_run(tmp_path / "missing", CONFIG).reason
    document = json.loads((same / "config.json").read_text())
    document["code"]["source_sha256"] = "0" * 64
    document["code"]["dependencies"]["numpy"] = "0.1"
    (same / "config.json").write_text(json.dumps(document))
    changed = reusable_run(same, CONFIG)
    assert not changed and "source changed" in changed.reason and "numpy 0.1 ->" in changed.reason


def test_a_run_made_on_another_kind_of_cpu_is_not_reused(tmp_path) -> None:
    stored = _stored_run(tmp_path / "r", CONFIG)
    document = json.loads((stored / "config.json").read_text())
    document["code"]["platform"]["cpu_vendor"] = "OtherVendor"
    (stored / "config.json").write_text(json.dumps(document))
    elsewhere = reusable_run(stored, CONFIG)
    assert not elsewhere and "another kind of machine" in elsewhere.reason
    assert "OtherVendor" in elsewhere.reason


def test_the_run_records_the_code_and_libraries(tmp_path) -> None:
    document = json.loads((_stored_run(tmp_path / "r", CONFIG) / "config.json").read_text())
    assert document["code"] == code_version()
    assert (
        document["code"]["dependencies"]["numpy"] and len(document["code"]["source_sha256"]) == 64
    )


def test_only_an_unfinished_run_can_be_resumed(tmp_path) -> None:
    done = _stored_run(tmp_path / "done", CONFIG)
    with pytest.raises(InvalidInputError, match="completed run; nothing to resume"):
        resumable_config(done)
    failed = _stored_run(tmp_path / "failed", CONFIG, "failed")
    assert resumable_config(failed) == CONFIG
    with pytest.raises(InvalidInputError, match="not a run directory"):
        resumable_config(tmp_path)


def test_view_images_are_written_on_a_worker_and_settled_before_the_outputs(tmp_path) -> None:
    rng = np.random.default_rng(0)
    images = [rng.integers(0, 255, (48, 64), dtype=np.uint8) for _ in range(5)]
    seen_by_outputs: list[bool] = []

    def work() -> str:
        for index, image in enumerate(images):
            assert run.write_image(f"car-1-{index:05d}", image) == f"images/car-1-{index:05d}.jpg"
            image[:] = 0  # the caller may reuse its array at once
        return "done"

    def write_outputs(end: RunEnd) -> None:
        seen_by_outputs.append(
            all(run.path(f"images/car-1-{i:05d}.jpg").exists() for i in range(5))
        )

    with RunDirectory(tmp_path / "run").claimed(CONFIG) as run:
        end = conduct_run(run, work, write_outputs, expected=(), what="mission")
    assert end.state == "completed" and seen_by_outputs == [True]
    decoded = cv2.imread(str(run.path("images/car-1-00004.jpg")), cv2.IMREAD_GRAYSCALE)
    assert decoded.shape == (48, 64) and decoded.std() > 20  # the image, not the zeros after it


def test_an_image_that_cannot_be_written_fails_the_run_in_one_line(tmp_path) -> None:
    def work() -> str:
        run.path("images").write_text("a file where the folder should be")
        run.write_image("car-1-00000", np.zeros((8, 8), dtype=np.uint8))
        return "done"

    run = RunDirectory(tmp_path / "run")
    with pytest.raises(SeminspectError, match="mission failed"), run.claimed(CONFIG):
        conduct_run(run, work, lambda end: None, expected=(), what="mission")
    assert read_run_status(run.root).state == "failed"


def test_the_last_status_lists_the_cached_arrays_the_run_used(tmp_path, monkeypatch) -> None:
    from seminspect.core.cache import CACHE_ENV, array_key, cached_array

    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "cache"))
    key = array_key("a grid's inputs")

    def one_run(name: str, uses_cache: bool) -> list[dict[str, str]]:
        run = RunDirectory(tmp_path / name, LAYOUT)
        with run.claimed(CONFIG):
            if uses_cache:
                cached_array("collision", key, lambda: np.arange(6.0))
            run.finish("completed")
        status = json.loads(run.path("status.json").read_text())
        return status["cache_entries"]

    assert [e["outcome"] for e in one_run("first", True)] == ["stored"]
    assert [(e["kind"], e["key"], e["outcome"]) for e in one_run("second", True)] == [
        ("collision", key, "hit")
    ]
    assert one_run("third", False) == []  # an earlier run's entries are not this one's
