"""A real ``seminspect sweep`` process sent SIGINT or SIGTERM after a finished mission: the
finished rows are written as a partial table, the others as interrupted, no earlier table
survives, and the exit code and the one line are the signal's."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from seminspect.runs.lock import LOCK_FILE
from seminspect.runs.sweep import TABLE_FILES

SRC = Path(__file__).resolve().parents[2] / "src"


def _run(seed: int) -> str:
    return f"subterranean-seed{seed}-time_budget_s=5"


def _start(out: Path, *args: str) -> subprocess.Popen:
    """Ten short tunnel missions, ``seminspect sweep *args``, in a process of its own."""
    env = {**os.environ, "PYTHONPATH": f"{SRC}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    command = [
        sys.executable, "-m", "seminspect.cli", "sweep", "--world", "subterranean",
        "--seeds", "0-9", "--set", "time_budget_s=5", "--out", str(out), *args,
    ]  # fmt: skip
    return subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)


def _stop_once_started(out: Path, child: subprocess.Popen, signum: int, seed: int) -> str:
    """Send ``signum`` once the mission of ``seed`` has started (the sweep has the row of an
    earlier one); the sweep's stderr."""
    deadline = time.monotonic() + 120
    try:
        while not (out / _run(seed)).exists():
            assert child.poll() is None, child.communicate()
            assert time.monotonic() < deadline, f"seed {seed} never started"
            time.sleep(0.1)
        assert not any((out / name).exists() for name in TABLE_FILES)  # the earlier sweep's
        child.send_signal(signum)
        _, err = child.communicate(timeout=60)
    finally:
        if child.poll() is None:  # a failed check must not leave the sweep running
            child.terminate()
            child.communicate(timeout=60)
    return err.decode()


def _earlier_tables(out: Path) -> None:
    out.mkdir()
    for name in TABLE_FILES:
        (out / name).write_text("an earlier sweep's table\n")


def _assert_partial(out: Path, reason: str) -> list[dict]:
    document = json.loads((out / "sweep.json").read_text())
    assert document["partial"] is True and document["stopped"] == reason
    runs = document["runs"]
    assert [r["name"] for r in runs] == [_run(seed) for seed in range(10)]
    assert runs[-1]["state"] == "interrupted" and reason in runs[-1]["error"]
    assert {r["state"] for r in runs} == {"completed", "interrupted"}
    assert (out / "sweep.md").read_text().startswith(f"**Partial table**: the sweep was {reason};")
    assert "interrupted" in (out / "sweep.csv").read_text()
    assert not list(out.glob(f"*/{LOCK_FILE}"))  # every mission let its directory go
    return runs


@pytest.mark.slow
@pytest.mark.parametrize(
    ("signum", "code", "reason"),
    [
        (signal.SIGINT, 130, "interrupted by the operator (Ctrl-C)"),
        (signal.SIGTERM, 143, "stopped by SIGTERM"),
    ],
)
def test_a_stopped_local_sweep_writes_a_partial_table(tmp_path, signum, code, reason) -> None:
    out = tmp_path / "sweep"
    _earlier_tables(out)
    child = _start(out, "--local")
    err = _stop_once_started(out, child, signum, seed=1)
    assert child.returncode == code, err
    assert err.strip().splitlines()[-1] == reason
    assert "Partial table" in err and "Traceback" not in err
    assert _assert_partial(out, reason)[0]["state"] == "completed"


@pytest.mark.slow
def test_sigterm_stops_a_ray_sweep_without_rays_stack_dump(tmp_path) -> None:
    pytest.importorskip("ray", reason="the 'sweep' extra (ray) is not installed")
    out = tmp_path / "sweep"
    _earlier_tables(out)
    child = _start(out, "--workers", "2")
    err = _stop_once_started(out, child, signal.SIGTERM, seed=2)  # after a row, 2 workers
    assert child.returncode == 143, err
    assert err.strip().splitlines()[-1] == "stopped by SIGTERM"
    assert "SIGTERM received" not in err and "Traceback" not in err
    _assert_partial(out, "stopped by SIGTERM")
