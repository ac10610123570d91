"""One writer per run directory: an exclusive ``flock`` on ``run.lock`` that names its holder.

The kernel drops the lock when the holder dies however it dies, so a leftover file from a killed
run is stale and is taken over with a warning.
"""

from __future__ import annotations

import fcntl
import os
import socket
import warnings
from pathlib import Path
from typing import IO

from seminspect.core.errors import SeminspectError

LOCK_FILE = "run.lock"


class RunDirectoryInUseError(SeminspectError):
    """Another live process is writing the run directory."""


class RunDirectoryWarning(UserWarning):
    """Something about a run directory the user should know, that does not stop the run."""


class RunLock:
    """The held lock of one run directory; :meth:`release` removes the file, then unlocks."""

    def __init__(self, path: Path, handle: IO[str]) -> None:
        self.path, self._handle = path, handle

    @classmethod
    def acquire(cls, path: Path) -> RunLock:
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
