"""The run directory: everything one run of a program made, written so that it is always valid.

Every program (the xFLIE mission, routine inspection, ...) writes the same frame::

    <run>/
      run.lock          held while a process writes the run; names that process
      status.json       state (running, completed, interrupted, failed) and why it stopped,
                        and at the end the cached arrays the run used (``core.cache``);
                        while running, the writer's pid, host and a heartbeat
      config.json       the fully resolved configuration and the code that ran it
      metrics.json      the program's figures, under the program's own format tag; written last
      summary.md        the same, for people
      events.jsonl      one JSON object per decision, rewritten whole at every checkpoint
      trajectory.csv    time, true and odometry pose of the robot
      images/           view images
      *.png, report.html  pictures

and the files of its own, which it names in a :class:`RunLayout`.

Every file is written atomically (temporary file, then rename), so an interrupted or failed
run leaves the previous complete version of each file, never half of one.

One process at a time writes a run directory: :meth:`RunDirectory.claimed` takes ``run.lock``
(:mod:`seminspect.runs.lock`), clears the files of the run that was there before (refusing a
directory that holds anything else), records the configuration and keeps a heartbeat in
``status.json`` (:mod:`seminspect.runs.status`).

A full disk still gets its last status written: ``status.json`` is rewritten in place when no
room is left for a second copy, and a run that cannot record even that says so
(:class:`StatusNotRecordedError`).
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import shutil
import socket
import threading
import time
from collections.abc import Iterator, Mapping, Sequence
from concurrent.futures import Future
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from seminspect.core.cache import cache_entries_used, reset_cache_entries_used
from seminspect.core.errors import InvalidInputError, SeminspectError
from seminspect.core.interrupts import as_interrupted
from seminspect.core.io import (
    atomic_write_bytes,
    atomic_write_text,
    dumps_json,
    read_versioned_json,
    rewrite_in_place,
    versioned_json_text,
    write_versioned_json,
)
from seminspect.core.provenance import code_version
from seminspect.core.threads import serial_worker
from seminspect.runs.lock import LOCK_FILE, RunLock
from seminspect.runs.status import HEARTBEAT_S, STATUS_FORMAT
from seminspect.runs.trajectory import TRAJECTORY_HEADER

#: ``config.json``'s tag; it has always said "mission", and every program's run shares it.
CONFIG_FORMAT = "seminspect.mission-config"
METRICS_FILE = "metrics.json"
#: The files every run may write at the top of its directory (pictures are ``*.png``).
COMMON_FILES = frozenset(
    {"status.json", "config.json", LOCK_FILE, "report.html", METRICS_FILE, "summary.md",
     "events.jsonl", "trajectory.csv"}
)  # fmt: skip
#: The folders every run may write, and the pattern of the files inside them.
COMMON_FOLDERS: Mapping[str, re.Pattern[str]] = {"images": re.compile(r".+\.jpg")}
#: A temporary file of an atomic write that was cut short: ``.<target>.<random>.<suffix>``.
_LEFTOVER = re.compile(r"\.(?P<target>.+)\.\w+\.\w+")
#: The errors of a disk (or a quota) with no room left.
_NO_ROOM = frozenset({errno.ENOSPC, errno.EDQUOT})


class StatusNotRecordedError(SeminspectError):
    """The last status of a run could not be written (a full disk): its ``status.json`` is out
    of date."""


def failure_reason(root: Path, exc: BaseException) -> str:
    """Why ``exc`` failed the run in ``root``, for its status: a file of the run that could not
    be written (a full disk) is named, e.g. ``no space left on device, writing graph.json``."""
    if isinstance(exc, OSError) and exc.filename is not None and exc.strerror:
        name, run = Path(os.fsdecode(exc.filename)).absolute(), root.absolute()
        why = exc.strerror[0].lower() + exc.strerror[1:]
        if name.is_relative_to(run):
            return f"{why}, writing {name.relative_to(run)}"
        return f"{why}: {exc.filename}"
    return f"{type(exc).__name__}: {exc}"


@dataclass(frozen=True)
class RunLayout:
    """What a program writes in its run directory besides the common files: its own files and
    folders (a folder with the pattern its files match), and the files a completed run holds,
    named when a stop cuts the outputs short."""

    files: frozenset[str] = frozenset()
    folders: Mapping[str, re.Pattern[str]] = field(default_factory=dict)
    outputs: Sequence[str] = ()

    def wrote(self, entry: Path) -> bool:
        """Whether ``entry`` (a file or folder of a run directory) is one a run of this layout
        writes, or the leftover of an atomic write of one that was cut short (a file, or the
        directory a bag is written in before its file is renamed out of it)."""
        if entry.is_dir() and not entry.is_symlink():
            if self._leftover(entry.name):
                return True
            pattern = self._folders.get(entry.name)
            return pattern is not None and all(
                pattern.fullmatch(f.name) or self._leftover(f.name) for f in entry.iterdir()
            )
        return self._is_file(entry.name) or self._leftover(entry.name)

    @property
    def _folders(self) -> Mapping[str, re.Pattern[str]]:
        return {**COMMON_FOLDERS, **self.folders}

    def _is_file(self, name: str) -> bool:
        if name.endswith(".png") and not name.startswith("."):
            return True
        return name in COMMON_FILES or name in self.files

    def _leftover(self, name: str) -> bool:
        """A temporary file of an atomic write (see ``core.io``) cut short by a kill."""
        match = _LEFTOVER.fullmatch(name)
        if match is None:
            return False
        target = match.group("target")
        return self._is_file(target) or any(p.fullmatch(target) for p in self._folders.values())


class RunDirectory:
    """Writer for one run's directory (see the module docstring)."""

    def __init__(self, root: str | os.PathLike[str], layout: RunLayout | None = None) -> None:
        self.root = Path(root)
        self.layout = layout or RunLayout()
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
    def fresh(
        base: str | os.PathLike[str], name: str, layout: RunLayout | None = None
    ) -> RunDirectory:
        """A new directory ``base/name``, or ``name-2``, ``name-3``, ... if it is taken."""
        parent = Path(base)
        candidate = parent / name
        suffix = 2
        while candidate.exists():
            candidate = parent / f"{name}-{suffix}"
            suffix += 1
        return RunDirectory(candidate, layout)

    def path(self, name: str) -> Path:
        return self.root / name

    @contextlib.contextmanager
    def claimed(self, config: dict[str, Any]) -> Iterator[RunDirectory]:
        """Own the directory for one run of ``config``: lock it, clear the previous run's files,
        record the configuration and the code, and keep a heartbeat until the block ends.

        A run that leaves the block without :meth:`finish` (an exception, a signal) is recorded
        as failed or interrupted before the exception goes on.
        """
        lock = RunLock.acquire(self.path(LOCK_FILE))
        heartbeat = threading.Event()
        self.finished = False
        try:
            clear_previous_run(self.root, self.layout)
            self._writer = {
                "pid": os.getpid(),
                "host": socket.gethostname(),
                "started": time.time(),
            }
            try:
                self.write_config(config)
                self.write_status("running")
                reset_cache_entries_used()  # the last status lists the cached arrays the run used
            except OSError as exc:  # a full disk: say so in the directory, if there is room
                self._record_stop(heartbeat, "failed", failure_reason(self.root, exc))
                raise
            beating = threading.Thread(target=self._beat, args=(heartbeat,), daemon=True)
            beating.start()
            try:
                yield self
            except KeyboardInterrupt as exc:
                self._record_stop(heartbeat, "interrupted", as_interrupted(exc).describe())
                raise
            except BaseException as exc:
                self._record_stop(heartbeat, "failed", failure_reason(self.root, exc))
                raise
            finally:
                heartbeat.set()
                beating.join()
        finally:
            lock.release()

    def _beat(self, stop: threading.Event) -> None:
        while not stop.wait(HEARTBEAT_S):
            # a heartbeat lost to a full disk: the last status will say what went wrong
            with self._status_lock, contextlib.suppress(OSError):
                if not self.finished:
                    self._write_status_unlocked("running", "")

    def _record_stop(self, heartbeat: threading.Event, state: str, reason: str) -> None:
        if not self.finished:
            heartbeat.set()
            self.finish(state, reason)

    def finish(self, state: str, reason: str = "") -> None:
        """The run's last status; a reader trusts it, so every output must already be on disk.

        On a full disk the file is rewritten in place; where even that fails,
        :class:`StatusNotRecordedError` says so and names the directory.
        """
        with self._status_lock:
            self.finished = True
            try:
                self._write_status_unlocked(state, reason, **self._last_details())
            except OSError as exc:
                if exc.errno not in _NO_ROOM:
                    raise
                self._rewrite_last_status(state, reason, exc)

    def _rewrite_last_status(self, state: str, reason: str, full: OSError) -> None:
        try:
            text = self._status_text(state, reason, **self._last_details())
            rewrite_in_place(self.path("status.json"), text.encode("utf-8"))
        except OSError as exc:
            ended = f"{state}: {reason}" if reason else state
            raise StatusNotRecordedError(
                f"{self.root}: could not record how the run ended ({ended}): "
                f"{failure_reason(self.root, full)}, which is out of date or missing; "
                "free some space and run it again"
            ) from exc

    @staticmethod
    def _last_details() -> dict[str, Any]:
        """What the last status adds: when the run ended and the cache entries it used
        (``core.cache``: a grid read back, stored or rebuilt after damage)."""
        return {"ended": time.time(), "cache_entries": cache_entries_used()}

    def write_status(self, state: str, reason: str = "", **details: Any) -> None:
        with self._status_lock:
            self._write_status_unlocked(state, reason, **details)

    def _write_status_unlocked(self, state: str, reason: str, **details: Any) -> None:
        atomic_write_text(self.path("status.json"), self._status_text(state, reason, **details))

    def _status_text(self, state: str, reason: str, **details: Any) -> str:
        now = time.time()
        writer = {**self._writer, "heartbeat": now} if self._writer else {}
        payload = {"state": state, "reason": reason, "updated": now, **writer, **details}
        return versioned_json_text(STATUS_FORMAT, 1, payload, indent=2)

    def write_config(self, config: dict[str, Any]) -> None:
        """The resolved configuration, with the code and library versions that run it."""
        payload = {"config": config, "code": code_version()}
        write_versioned_json(self.path("config.json"), CONFIG_FORMAT, 1, payload, indent=2)

    def write_metrics(self, kind: str, metrics: dict[str, Any]) -> None:
        """``metrics.json`` under the program's own format tag; a reader takes its presence as
        the end of the run's outputs, so it is written last."""
        write_versioned_json(self.path(METRICS_FILE), kind, 1, metrics, indent=2)

    def write_summary(self, markdown: str) -> None:
        atomic_write_text(self.path("summary.md"), markdown)

    def write_trajectory(self, rows: Sequence[Sequence[float]], robot: str | None = None) -> None:
        """Rows of ``t, x, y, z, yaw, odom_x, odom_y, odom_z, odom_yaw``; a robot of a team
        writes ``robots/<robot>-trajectory.csv``."""
        header = TRAJECTORY_HEADER + "\n"
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


def _write_jpeg(target: Path, name: str, image: NDArray[np.uint8]) -> Path:
    ok, encoded = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, 90])
    if not ok:
        raise InvalidInputError(f"could not encode image {name}")
    return atomic_write_bytes(target, encoded.tobytes())


def clear_previous_run(root: Path, layout: RunLayout) -> None:
    """Remove what an earlier run left in ``root``, so no file of it sits beside the new run's;
    refuse, deleting nothing, when ``root`` holds anything a run does not write."""
    strangers = [entry.name for entry in sorted(root.iterdir()) if not layout.wrote(entry)]
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


def read_run_config(run_dir: Path) -> dict[str, Any]:
    """The resolved configuration a run was made with, as its program recorded it."""
    return read_versioned_json(run_dir / "config.json", CONFIG_FORMAT, [1])["config"]


def load_events(run_dir: Path) -> list[dict[str, Any]]:
    """The decisions a run logged (``events.jsonl``), in order; none when it has no log."""
    path = run_dir / "events.jsonl"
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines() if line]
