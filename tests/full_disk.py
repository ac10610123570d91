"""A full disk for tests: flushing chosen files to disk fails with ``ENOSPC``, as it does when
no space is left (the error names no file, as the system's does)."""

from __future__ import annotations

import errno
import os
import re
from pathlib import Path

import pytest

#: The temporary file of an atomic write of ``<target>`` (see ``seminspect.core.io``).
_TEMPORARY = re.compile(r"\.(?P<target>.+)\.\w+\.\w+")


def fill_disk(monkeypatch: pytest.MonkeyPatch, *names: str, in_place: bool = False) -> None:
    """From now on writing a new copy of a file named in ``names`` (any file, if none are
    named) fails; with ``in_place``, so does rewriting a file in its own blocks."""
    flush = os.fsync

    def fsync(fd: int) -> None:
        name = Path(f"/proc/self/fd/{fd}").readlink().name
        temporary = _TEMPORARY.fullmatch(name)
        if in_place if temporary is None else not names or temporary.group("target") in names:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        flush(fd)

    monkeypatch.setattr(os, "fsync", fsync)
