"""The run directory: everything one mission made, written so that it is always valid.

Layout::

    <run>/
      run.lock          held while a process writes the run; names that process
      status.json       state (running, completed, interrupted, failed) and why it stopped;
                        while running, the writer's pid, host and a heartbeat
      config.json       the fully resolved mission configuration and the code that ran it
      graph.json        the final 3DLSG (seminspect.lsg JSON; `seminspect graph ...` reads it)
      snapshots/        the graph after each inspected target, named by simulated time
      trajectory.csv    time, true and odometry pose of the robot (a team: the explorer)
      robots/           a team's robots: <robot>-trajectory.csv for each
      events.jsonl      one JSON object per decision (survey, selection, arrival, level, ...),
                        rewritten whole at every checkpoint
      metrics.json      Table 3 and Table 6 figures, mission time, distance
      map.npz           the robot's final occupancy map (seminspect.voxel-map)
      summary.md        the same, for people
      images/           the view images the graph refers to
      *.png             pictures

Every file is written atomically (temporary file, then rename), so an interrupted or failed
run leaves the previous complete version of each file, never half of one.

One process at a time writes a run directory: :meth:`RunDirectory.claimed` takes ``run.lock``
(an ``flock`` the kernel drops when the process dies, so a killed run's lock is taken over with
a warning), clears the files of the run that was there before (refusing a directory that holds
anything else), records the configuration and keeps a heartbeat in ``status.json``.
:func:`read_run_status` reports a run whose writer is gone as ``dead`` or ``abandoned``.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import re
import shutil
import socket
import threading
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import cv2
import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError, InvalidInputError, SeminspectError
from seminspect.core.interrupts import Interrupted, as_interrupted, deferred_signals
from seminspect.core.io import (
    atomic_write_bytes,
    atomic_write_text,
    dumps_json,
    read_versioned_json,
    write_versioned_json,
)
from seminspect.core.provenance import code_differences, code_version
from seminspect.core.threads import serial_worker
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.io import save_graph
from seminspect.mapping.voxel import VoxelMap, save_map
from seminspect.missions.xflie.metrics import MissionMetrics
from seminspect.worlds import World, open_world

if TYPE_CHECKING:
    from seminspect.missions.xflie.config import MissionConfig

STATUS_FORMAT = "seminspect.run-status"
METRICS_FORMAT = "seminspect.run-metrics"
CONFIG_FORMAT = "seminspect.mission-config"
MAP_FILE = "map.npz"
LOCK_FILE = "run.lock"
#: The files a finished run holds; a completed run has every one of them.
OUTPUT_FILES = (
    "graph.json", MAP_FILE, "trajectory.csv", "events.jsonl", "summary.md", "metrics.json",
)  # fmt: skip
#: What a routine run (002) writes besides the common files.
ROUTINE_FILES = ("tour.json", "views.csv")
#: Everything a run of any kind writes at the top of its directory (pictures are ``*.png``).
RUN_FILES = frozenset(
    {"status.json", "config.json", LOCK_FILE, "report.html", *OUTPUT_FILES, *ROUTINE_FILES}
)
#: Folders a run writes, and the pattern of the files inside them.
RUN_FOLDERS = {
    "snapshots": re.compile(r"graph-[\d.]+s\.json"),
    "images": re.compile(r".+\.jpg"),
    "prior": re.compile(r"map\.npz"),
    "robots": re.compile(r"[a-z]+-trajectory\.csv"),
}
#: A temporary file of an atomic write that was cut short: ``.<target>.<random>.<suffix>``.
_LEFTOVER = re.compile(r"\.(?P<target>.+)\.\w+\.\w+")
#: Seconds between heartbeats, and the age after which a silent run counts as abandoned.
HEARTBEAT_S = 5.0
STALE_AFTER_S = 120.0


class RunDirectoryInUseError(SeminspectError):
    """Another live process is writing the run directory."""


class RunDirectoryWarning(UserWarning):
    """Something about a run directory the user should know, that does not stop the run."""


class RunDirectory:
    """Writer for one run's directory (see the module docstring)."""

    def __init__(self, root: str | os.PathLike[str]) -> None:
        self.root = Path(root)
        if self.root.exists() and not self.root.is_dir():
            raise InvalidInputError(
                f"{self.root} exists and is not a directory; choose another --out"
            )
        try:
            self.root.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InvalidInputError(
                f"cannot create run directory {self.root} ({exc.strerror}); choose another --out"
            ) from None
        self._events: list[dict[str, Any]] = []
        self._image_writes: list[Future[Path]] = []
        self._status_lock = threading.Lock()
        self._writer: dict[str, Any] | None = None  # pid, host, started while this process runs it
        self.finished = False

    @staticmethod
    def fresh(base: str | os.PathLike[str], name: str) -> RunDirectory:
        """A new directory ``base/name``, or ``name-2``, ``name-3``, ... if it is taken."""
        parent = Path(base)
        candidate = parent / name
        suffix = 2
        while candidate.exists():
            candidate = parent / f"{name}-{suffix}"
            suffix += 1
        return RunDirectory(candidate)

    def path(self, name: str) -> Path:
        return self.root / name

    @contextlib.contextmanager
    def claimed(self, config: dict[str, Any]) -> Iterator[RunDirectory]:
        """Own the directory for one run of ``config``: lock it, clear the previous run's files,
        record the configuration and the code, and keep a heartbeat until the block ends.

        A run that leaves the block without :meth:`finish` (an exception, a signal) is recorded
        as failed or interrupted before the exception goes on.
        """
        lock = _RunLock.acquire(self.path(LOCK_FILE))
        heartbeat = threading.Event()
        self.finished = False
        try:
            clear_previous_run(self.root)
            self.write_config(config)
            self._writer = {
                "pid": os.getpid(),
                "host": socket.gethostname(),
                "started": time.time(),
            }
            self.write_status("running")
            beating = threading.Thread(target=self._beat, args=(heartbeat,), daemon=True)
            beating.start()
            try:
                yield self
            except KeyboardInterrupt as exc:
                self._record_stop(heartbeat, "interrupted", as_interrupted(exc).describe())
                raise
            except BaseException as exc:
                self._record_stop(heartbeat, "failed", f"{type(exc).__name__}: {exc}")
                raise
            finally:
                heartbeat.set()
                beating.join()
        finally:
            lock.release()

    def _beat(self, stop: threading.Event) -> None:
        while not stop.wait(HEARTBEAT_S):
            with self._status_lock:
                if not self.finished:
                    self._write_status_unlocked("running", "")

    def _record_stop(self, heartbeat: threading.Event, state: str, reason: str) -> None:
        if not self.finished:
            heartbeat.set()
            self.finish(state, reason)

    def finish(self, state: str, reason: str = "") -> None:
        """The run's last status; a reader trusts it, so every output must already be on disk."""
        with self._status_lock:
            self.finished = True
            self._write_status_unlocked(state, reason, ended=time.time())

    def write_status(self, state: str, reason: str = "", **details: Any) -> None:
        with self._status_lock:
            self._write_status_unlocked(state, reason, **details)

    def _write_status_unlocked(self, state: str, reason: str, **details: Any) -> None:
        now = time.time()
        writer = {**self._writer, "heartbeat": now} if self._writer else {}
        payload = {"state": state, "reason": reason, "updated": now, **writer, **details}
        write_versioned_json(self.path("status.json"), STATUS_FORMAT, 1, payload, indent=2)

    def write_config(self, config: dict[str, Any]) -> None:
        """The resolved configuration, with the code and library versions that run it."""
        payload = {"config": config, "code": code_version()}
        write_versioned_json(self.path("config.json"), CONFIG_FORMAT, 1, payload, indent=2)

    def write_graph(self, graph: LayeredSemanticGraph, snapshot_time: float | None = None) -> Path:
        """The final graph, or a snapshot named by simulated time."""
        if snapshot_time is None:
            return save_graph(graph, self.path("graph.json"))
        return save_graph(graph, self.path(f"snapshots/graph-{snapshot_time:08.1f}s.json"))

    def write_metrics(self, metrics: dict[str, Any]) -> None:
        write_versioned_json(self.path("metrics.json"), METRICS_FORMAT, 1, metrics, indent=2)

    def write_map(self, occupancy: VoxelMap) -> Path:
        """The robot's occupancy map as it was at the end of the run."""
        return save_map(self.path(MAP_FILE), occupancy)

    def write_summary(self, markdown: str) -> None:
        atomic_write_text(self.path("summary.md"), markdown)

    def write_trajectory(self, rows: Sequence[Sequence[float]], robot: str | None = None) -> None:
        """Rows of ``t, x, y, z, yaw, odom_x, odom_y, odom_z, odom_yaw``; a robot of a team
        writes ``robots/<robot>-trajectory.csv``."""
        header = "t,x,y,z,yaw,odom_x,odom_y,odom_z,odom_yaw\n"
        body = "".join(",".join(f"{v:.4f}" for v in row) + "\n" for row in rows)
        name = "trajectory.csv" if robot is None else f"robots/{robot}-trajectory.csv"
        atomic_write_text(self.path(name), header + body)

    def write_image(self, name: str, image: NDArray[np.uint8]) -> str:
        """Save a view image as JPEG; returns its path relative to the run directory.

        The image is encoded and written on a worker thread (``serial_worker("images")``) while
        the mission goes on; :meth:`settle_images` waits for every image handed over, and
        :func:`conduct_run` does so before the run's outputs and last status are written.
        """
        relative = f"images/{name}.jpg"
        target = self.path(relative)
        self._image_writes.append(
            serial_worker("images").submit(_write_jpeg, target, name, image.copy())
        )
        return relative

    def settle_images(self) -> None:
        """Wait for the images handed to the worker thread; the first failure is raised."""
        pending, self._image_writes = self._image_writes, []
        for write in pending:
            write.result()

    def log_event(self, kind: str, sim_time: float, **fields: Any) -> None:
        """Record one decision; :meth:`flush_events` writes them all."""
        self._events.append({"t": round(sim_time, 3), "event": kind, **fields})

    def flush_events(self) -> None:
        """Rewrite ``events.jsonl`` atomically with every event so far."""
        lines = "".join(dumps_json(event) + "\n" for event in self._events)
        atomic_write_text(self.path("events.jsonl"), lines)

    @property
    def events(self) -> list[dict[str, Any]]:
        return list(self._events)


@dataclass
class RunEnd:
    """How a run ended: its last state, why, and the error or stop signal behind it."""

    state: str = "completed"
    reason: str = ""
    error: Exception | None = None
    stop: Interrupted | None = field(default=None, repr=False)

    @property
    def signum(self) -> int | None:
        """The signal that stopped the run, if one did."""
        return self.stop.signum if self.stop else None


def _write_jpeg(target: Path, name: str, image: NDArray[np.uint8]) -> Path:
    ok, encoded = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, 90])
    if not ok:
        raise InvalidInputError(f"could not encode image {name}")
    return atomic_write_bytes(target, encoded.tobytes())


def conduct_run(
    run: RunDirectory,
    work: Callable[[], str],
    write_outputs: Callable[[RunEnd], None],
    *,
    expected: Sequence[str],
    what: str,
) -> RunEnd:
    """Do ``work`` (it returns why it stopped), then ``write_outputs`` whatever happened, then
    the last status, which is truthful: a stop while writing names the ``expected`` files that
    were not written. A failure is re-raised once the directory is complete, as a
    :class:`SeminspectError` naming ``what`` failed and where the partial results are."""
    end = RunEnd()
    try:
        end.reason = work()
        run.settle_images()
    except KeyboardInterrupt as exc:
        end.stop = as_interrupted(exc)
        end.state, end.reason = "interrupted", end.stop.describe()
    except Exception as exc:
        end.state, end.reason, end.error = "failed", f"{type(exc).__name__}: {exc}", exc
    try:
        run.settle_images()  # those of work that stopped early
        write_outputs(end)
    except KeyboardInterrupt as exc:
        end.stop = end.stop or as_interrupted(exc)
        end.state = "interrupted"
        end.reason = _cut_short(run, end.reason, end.stop.describe(), expected)
    except Exception as exc:
        failure = f"finishing the run failed: {type(exc).__name__}: {exc}"
        end.state, end.reason = "failed", _cut_short(run, end.reason, failure, expected)
        end.error = end.error or exc
    with deferred_signals():  # a second signal must not cut the last status short
        run.finish(end.state, end.reason)
    if end.error is not None:
        if isinstance(end.error, SeminspectError):
            raise end.error
        raise SeminspectError(
            f"{what} failed ({end.reason}); partial results in {run.root}"
        ) from end.error
    return end


def _cut_short(run: RunDirectory, reason: str, why: str, expected: Sequence[str]) -> str:
    """The reason of a run stopped while writing its outputs, naming the ones not written."""
    missing = [name for name in expected if not run.path(name).exists()]
    note = f"{why} while writing the outputs" + (
        f"; not written: {', '.join(missing)}" if missing else ""
    )
    return f"{reason}; {note}" if reason else note


class _RunLock:
    """An exclusive ``flock`` on ``run.lock``, which names its holder. The kernel drops the lock
    when the holder dies however it dies, so a leftover file from a killed run is stale."""

    def __init__(self, path: Path, handle: IO[str]) -> None:
        self.path, self._handle = path, handle

    @classmethod
    def acquire(cls, path: Path) -> _RunLock:
        handle = path.open("a+", encoding="utf-8")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _read_holder(handle)
            handle.close()
            raise RunDirectoryInUseError(
                f"{path.parent} is in use by another run (process {holder}); "
                "wait for it to end, stop it, or choose another --out"
            ) from None
        previous = _read_holder(handle)
        if previous:
            warnings.warn(
                f"{path.parent}: taking over the lock of process {previous}, which is gone",
                RunDirectoryWarning,
                stacklevel=4,
            )
        handle.seek(0)
        handle.truncate()
        handle.write(f"{os.getpid()} {socket.gethostname()}\n")
        handle.flush()
        return cls(path, handle)

    def release(self) -> None:
        self.path.unlink(missing_ok=True)  # first: no one may read our pid once we are gone
        self._handle.close()


def _read_holder(handle: IO[str]) -> str:
    handle.seek(0)
    fields = handle.read().split()
    return " on ".join(fields[:2])


def clear_previous_run(root: Path) -> None:
    """Remove what an earlier run left in ``root``, so no file of it sits beside the new run's;
    refuse, deleting nothing, when ``root`` holds anything a run does not write."""
    strangers = [entry.name for entry in sorted(root.iterdir()) if not _written_by_a_run(entry)]
    if strangers:
        shown = ", ".join(strangers[:3]) + (
            f" and {len(strangers) - 3} more" if len(strangers) > 3 else ""
        )
        raise InvalidInputError(
            f"{root} holds files that are not a run's ({shown}); "
            "choose an empty directory or a new --out"
        )
    for entry in root.iterdir():
        if entry.name == LOCK_FILE:
            continue
        if entry.is_dir():
            shutil.rmtree(entry)
        else:
            entry.unlink()


def _written_by_a_run(entry: Path) -> bool:
    if entry.is_dir() and not entry.is_symlink():
        pattern = RUN_FOLDERS.get(entry.name)
        return pattern is not None and all(
            pattern.fullmatch(f.name) or _is_leftover(f.name) for f in entry.iterdir()
        )
    return _is_run_file(entry.name) or _is_leftover(entry.name)


def _is_run_file(name: str) -> bool:
    return name in RUN_FILES or (name.endswith(".png") and not name.startswith("."))


def _is_leftover(name: str) -> bool:
    """A temporary file of an atomic write (see ``core.io``) cut short by a kill."""
    match = _LEFTOVER.fullmatch(name)
    if match is None:
        return False
    target = match.group("target")
    return _is_run_file(target) or any(p.fullmatch(target) for p in RUN_FOLDERS.values())


def read_run_config(run_dir: Path) -> dict[str, Any]:
    """The resolved mission configuration a run was made with."""
    return read_versioned_json(run_dir / "config.json", CONFIG_FORMAT, [1])["config"]


def read_metrics_document(run_dir: Path) -> dict[str, Any]:
    """The ``metrics.json`` any run (mission, routine) wrote when it ended, as stored."""
    return read_versioned_json(run_dir / "metrics.json", METRICS_FORMAT, [1])


def read_run_metrics(run_dir: Path) -> MissionMetrics:
    """The metrics a mission wrote when it ended."""
    return MissionMetrics.from_json(read_metrics_document(run_dir))


@dataclass(frozen=True)
class Reuse:
    """Whether a stored run can stand for a new one; false with the reason when it cannot."""

    reason: str = ""

    def __bool__(self) -> bool:
        return not self.reason


def reusable_run(run_dir: Path, config: MissionConfig) -> Reuse:
    """Whether ``run_dir`` holds a completed run of exactly ``config``, with its map, made by the
    same code and libraries as this process on the same kind of CPU (the reason when not)."""
    try:
        status = read_run_status(run_dir)
        document = read_versioned_json(run_dir / "config.json", CONFIG_FORMAT, [1])
    except FileFormatError as exc:
        return Reuse(f"no readable run: {exc}")
    return Reuse(_why_not_reusable(run_dir, status, document, config))


def _why_not_reusable(
    run_dir: Path, status: RunStatus, document: dict[str, Any], config: MissionConfig
) -> str:
    if status.state != "completed":
        return f"{run_dir} is {status.state}, not completed"
    changed = _changed_settings(document["config"], config.model_dump(mode="json"))
    if changed:
        return f"{run_dir} ran another configuration ({', '.join(changed)})"
    if not (run_dir / MAP_FILE).is_file():
        return f"{run_dir} has no {MAP_FILE}"
    if "code" not in document:
        return f"{run_dir} does not record the code that made it"
    differences = code_differences(document["code"], code_version())
    return (
        f"{run_dir} was made by other code or on another kind of machine: {'; '.join(differences)}"
        if differences
        else ""
    )


def _changed_settings(stored: dict[str, Any], wanted: dict[str, Any]) -> list[str]:
    keys = sorted(set(stored) | set(wanted))
    return [
        f"{k}: {stored.get(k)!r} -> {wanted.get(k)!r}"
        for k in keys
        if stored.get(k) != wanted.get(k)
    ]


@dataclass(frozen=True)
class RunStatus:
    """What ``status.json`` says, judged against the living: ``state`` is ``dead`` when the
    writing process is gone and ``abandoned`` when its heartbeat stopped; ``recorded`` is the
    state the file itself holds."""

    state: str
    recorded: str
    reason: str
    pid: int | None
    host: str | None
    heartbeat: float | None


def read_run_status(run_dir: Path) -> RunStatus:
    """The state of the run in ``run_dir``, a ``running`` one checked for a live writer."""
    status = read_versioned_json(run_dir / "status.json", STATUS_FORMAT, [1])
    recorded, reason = str(status.get("state")), str(status.get("reason", ""))
    pid, host, beat = status.get("pid"), status.get("host"), status.get("heartbeat")
    state = recorded
    if recorded == "running":
        if host == socket.gethostname() and isinstance(pid, int) and not _process_alive(pid):
            state, reason = "dead", f"process {pid} stopped without recording why (killed?)"
        elif not isinstance(beat, int | float) or time.time() - beat > STALE_AFTER_S:
            state = "abandoned"
            reason = f"no heartbeat from process {pid} on {host} for over {STALE_AFTER_S:.0f} s"
    return RunStatus(state, recorded, reason, pid, host, beat)


def _process_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # alive, but another user's
        return True
    return True


def resumable_config(run_dir: Path) -> dict[str, Any]:
    """The configuration of a run that stopped before completing, to run again from the start;
    :class:`InvalidInputError` saying why when there is nothing to resume."""
    if not (run_dir / "config.json").is_file():
        raise InvalidInputError(f"{run_dir} is not a run directory (no config.json)")
    config = read_run_config(run_dir)
    try:
        status = read_run_status(run_dir)
    except FileFormatError:
        return config  # killed before its first status: nothing ran yet
    if status.state == "completed":
        raise InvalidInputError(
            f"{run_dir} holds a completed run; nothing to resume (run it again with --out)"
        )
    if status.state == "running":
        raise RunDirectoryInUseError(
            f"{run_dir} is being written by process {status.pid} on {status.host}; "
            "wait for it to end or stop it first"
        )
    return config


def load_run_world(run_dir: Path) -> World:
    """Regenerate the world a run used (worlds are deterministic under their seed)."""
    config = read_run_config(run_dir)
    return open_world(config["world"], config["scenario"], seed=config["seed"])


def load_robot_trajectories(run_dir: Path) -> dict[str, NDArray[np.float64]]:
    """Each team robot's trajectory by name (empty for a one-robot run)."""
    folder = run_dir / "robots"
    paths = sorted(folder.glob("*-trajectory.csv")) if folder.is_dir() else []
    return {path.name.removesuffix("-trajectory.csv"): read_trajectory(path) for path in paths}


def load_trajectory(run_dir: Path) -> NDArray[np.float64]:
    """Rows of ``t, x, y, z, yaw, odom_x, odom_y, odom_z, odom_yaw`` (none when absent)."""
    return read_trajectory(run_dir / "trajectory.csv")


def read_trajectory(path: Path) -> NDArray[np.float64]:
    """A trajectory file's rows (see :func:`load_trajectory`); none when it is absent."""
    if not path.exists():
        return np.empty((0, 9))
    try:
        return np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except ValueError as exc:
        raise FileFormatError(f"{path}: {exc}") from None
