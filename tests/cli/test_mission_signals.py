"""A real ``seminspect mission`` process sent SIGINT, SIGTERM and SIGKILL mid-mission: every
signal leaves a truthful, loadable run directory and the right exit code."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from seminspect.graphs.lsg.io import load_graph
from seminspect.runs.lock import LOCK_FILE
from seminspect.runs.status import read_run_status

SRC = Path(__file__).resolve().parents[2] / "src"


def _start(*args: str) -> subprocess.Popen:
    """``seminspect mission --no-pictures *args`` in a process of its own."""
    env = {**os.environ, "PYTHONPATH": f"{SRC}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    command = [sys.executable, "-m", "seminspect.cli", "mission", "--no-pictures", *args]
    return subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)


def _wait_until(ready, child: subprocess.Popen, timeout: float = 120) -> None:
    """Until ``ready()``, checking that the mission is still going."""
    deadline = time.monotonic() + timeout
    while not ready():
        assert child.poll() is None, child.communicate()
        assert time.monotonic() < deadline, "the mission never got there"
        time.sleep(0.2)


def _status(out: Path) -> dict:
    return json.loads((out / "status.json").read_text())


@pytest.mark.slow
@pytest.mark.parametrize(
    ("signum", "code", "reason"), [(signal.SIGINT, 130, "Ctrl-C"), (signal.SIGTERM, 143, "SIGTERM")]
)
def test_a_stop_signal_ends_the_mission_truthfully(tmp_path, signum, code, reason) -> None:
    out = tmp_path / "run"
    child = _start("--world", "subterranean", "--out", str(out))
    _wait_until(lambda: any((out / "images").glob("*.jpg")), child)  # inspecting a target
    child.send_signal(signum)
    _, err = child.communicate(timeout=60)
    assert child.returncode == code, err
    status = _status(out)
    assert status["state"] == "interrupted" and reason in status["reason"]
    assert load_graph(out / "graph.json").targets()
    assert (out / "metrics.json").exists() and not (out / LOCK_FILE).exists()
    assert "partial results" in err.decode()


@pytest.mark.slow
def test_a_killed_mission_reads_as_dead_and_resumes_to_completion(tmp_path) -> None:
    out = tmp_path / "run"
    child = _start("--world", "subterranean", "--budget", "40", "--out", str(out))
    _wait_until((out / "status.json").exists, child)  # exploring
    child.kill()
    child.wait()
    assert _status(out)["state"] == "running"  # what the file says ...
    assert read_run_status(out).state == "dead"  # ... and what a reader concludes
    assert not (out / "graph.json").exists()
    resumed = _start("--resume", str(out))
    _, err = resumed.communicate(timeout=300)
    assert resumed.returncode == 0, err
    assert f"lock of process {child.pid}" in err.decode()
    assert _status(out)["state"] == "completed" and load_graph(out / "graph.json").targets()
    assert json.loads((out / "config.json").read_text())["config"]["time_budget_s"] == 40
