"""One exit-code policy for every long command: a real process sent SIGINT or SIGTERM once its
work is under way ends with one line saying which signal stopped it and exit code 128 plus the
signal (130, 143).

Each command runs twice (once per signal) from one module fixture, a few processes at a time,
so the file costs about as long as the commands take to get going.
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[2] / "src"
TESTS = SRC.parent / "tests"
LINES = {
    signal.SIGINT: "interrupted by the operator (Ctrl-C)",
    signal.SIGTERM: "stopped by SIGTERM",
}
#: Terminal control sequences of rich's live progress display.
_CONTROL = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")
#: The terrain command's encoder, a plug-in module in the process's folder: no model to load.
_ENCODER_PLUGIN = """
from conftest import HashingTextEncoder
from seminspect.perception.encoders import CaptionEncoder


def make():
    return CaptionEncoder(HashingTextEncoder())
"""


@dataclass(frozen=True)
class Command:
    """``seminspect ARGS`` (``{out}`` is the process's folder), under way once ``ready``."""

    args: str
    ready: Callable[[Path, str], bool]  # (folder, everything printed so far) -> under way
    needs: str | None = None  # a module the command cannot run without


def _has(*pattern: str) -> Callable[[Path, str], bool]:
    return lambda out, _: any(out.glob("/".join(pattern)))


def _printed(pattern: str) -> Callable[[Path, str], bool]:
    return lambda _, printed: re.search(pattern, printed) is not None


COMMANDS = {
    "mission": Command(
        "mission -w subterranean --budget 20 --no-pictures -o {out}/run",
        _has("run", "status.json"),
    ),
    "routine inspect": Command(
        "routine inspect --length 10 --no-pictures -o {out}/run", _has("run", "status.json")
    ),
    "terrain map": Command(
        "terrain map -s small --encoder sig_encoder:make --out {out}/c.npz",
        _printed(r"scanning and fusing \S* [1-9]\d*/\d+"),  # a frame fused
    ),
    "rl train": Command(
        "rl train --steps 1000000 --envs 4 -o {out}/train",
        _has("train", "progress.csv"),
        needs="torch",
    ),
    "rl eval": Command(
        "rl eval --obstacles 0 -n 64 --envs 4 -o {out}/eval",
        _printed("shipped: 0 obstacles"),  # the episodes are being flown
        needs="torch",
    ),
    "sweep": Command(
        "sweep -w subterranean --seeds 0-3 --set time_budget_s=20 --workers 1 -o {out}/sweep",
        _has("sweep", "*", "status.json"),  # a mission under way
        needs="ray",
    ),
}


@dataclass
class Stopped:
    """How one stopped process ended: its exit code and what it printed."""

    code: int | None
    out: str
    err: str


def _environment(folder: Path) -> dict[str, str]:
    paths = [str(SRC), str(TESTS), str(folder), os.environ.get("PYTHONPATH", "")]
    # rich then draws its progress bars into the output files, where readiness shows
    terminal = {"TTY_COMPATIBLE": "1", "TTY_INTERACTIVE": "1"}
    return {**os.environ, "PYTHONPATH": os.pathsep.join(paths), **terminal}


def _start(command: Command, folder: Path) -> subprocess.Popen:
    folder.mkdir(parents=True)
    (folder / "sig_encoder.py").write_text(_ENCODER_PLUGIN)
    args = command.args.replace("{out}", str(folder)).split()
    with (folder / "stdout").open("wb") as out, (folder / "stderr").open("wb") as err:
        return subprocess.Popen(
            [sys.executable, "-m", "seminspect.cli", *args],
            cwd=folder,
            env=_environment(folder),
            stdout=out,
            stderr=err,
        )


def _read(folder: Path, name: str) -> str:
    return _CONTROL.sub("", (folder / name).read_text(errors="replace"))


@dataclass
class _Child:
    """One command's process, its folder and the signal it gets once under way."""

    name: str
    signum: int
    folder: Path
    process: subprocess.Popen | None = None
    signalled: bool = False

    def step(self) -> bool:
        """Start, signal or let be; whether the process has ended."""
        if self.process is None:
            self.process = _start(COMMANDS[self.name], self.folder)
        elif self.process.poll() is not None:  # ended (on its own, if not signalled)
            return True
        elif not self.signalled and COMMANDS[self.name].ready(self.folder, self._printed()):
            self.process.send_signal(self.signum)
            self.signalled = True
        return False

    def _printed(self) -> str:
        return _read(self.folder, "stdout") + _read(self.folder, "stderr")


def _run_all(children: list[_Child], timeout: float = 900, grace: float = 60) -> None:
    """Run the children a few at a time (they wait on imports as much as on a core), never two
    of one command at once (two sweeps would share one machine's Ray).

    ``timeout`` bounds the whole run generously: on a loaded two-core machine the twelve
    children take minutes, and one cut off by the deadline mid-exit reads as a hang. A child
    signalled before the deadline gets ``grace`` seconds more to end."""
    pending = sorted(children, key=lambda c: c.signum)
    running: list[_Child] = []
    deadline = time.monotonic() + timeout
    while (pending or running) and time.monotonic() < deadline:
        busy = {child.name for child in running}
        free = [child for child in pending if child.name not in busy]
        for child in free[: (os.cpu_count() or 1) + 1 - len(running)]:
            pending.remove(child)
            running.append(child)
        running = [child for child in running if not child.step()]
        time.sleep(0.1)
    for child in running:
        if child.signalled and child.process is not None:
            # a real hang stays without an exit code, and the test says so
            with contextlib.suppress(subprocess.TimeoutExpired):
                child.process.wait(timeout=grace)


@pytest.fixture(scope="module")
def stopped(tmp_path_factory) -> Iterator[dict[tuple[str, int], Stopped]]:
    """Every command, once per stop signal, stopped once under way."""
    root = tmp_path_factory.mktemp("signals")
    children = [
        _Child(name, signum, root / f"{name.replace(' ', '-')}-{signum}")
        for name, command in COMMANDS.items()
        if command.needs is None or importlib.util.find_spec(command.needs) is not None
        for signum in LINES
    ]
    try:
        _run_all(children)
        yield {
            (child.name, child.signum): Stopped(
                child.process.returncode if child.process else None,
                _read(child.folder, "stdout"),
                _read(child.folder, "stderr"),
            )
            for child in children
        }
    finally:
        for child in children:
            if child.process is not None and child.process.poll() is None:
                child.process.kill()
                child.process.wait()


@pytest.mark.slow
@pytest.mark.parametrize("signum", list(LINES), ids=["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("name", list(COMMANDS))
def test_a_stop_signal_ends_every_command_with_its_line_and_code(stopped, name, signum) -> None:
    needs = COMMANDS[name].needs
    if needs is not None:
        pytest.importorskip(needs, reason=f"{name} needs {needs}, which is not installed")
    result = stopped[name, signum]
    lines = [line.strip() for line in result.err.splitlines() if line.strip()]
    last = "\n".join(lines[-4:])  # the end of the output, below the progress bars
    assert result.code == 128 + signum, last
    assert any(line.startswith(LINES[signum]) for line in lines), last
    assert "Traceback" not in result.err + result.out, last
