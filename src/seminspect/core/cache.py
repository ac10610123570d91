"""An on-disk cache of arrays that are slow to compute and fully determined by their inputs.

A world's collision grids take seconds to build and are rebuilt by every mission on the same
world; here they are stored once, under a key that hashes everything they are computed from,
and read back in milliseconds. A changed input gives another key, so a stale array is never
read: callers put into the key every input array and parameter, and the source of the code
that computes it (:func:`source_digest`).

The cache lives in ``$SEMINSPECT_CACHE_DIR``, else ``$XDG_CACHE_HOME/seminspect``, else
``~/.cache/seminspect``; ``SEMINSPECT_CACHE_DIR=off`` turns it off. Files are written
atomically (``core.io``); a cache that cannot be read or written only costs the rebuild. The
folder is kept under ``$SEMINSPECT_CACHE_MAX_MB`` (default 2,048 MB): after each store the files
used least recently (a read counts as a use) are deleted until it fits.
"""

from __future__ import annotations

import hashlib
import math
import os
from collections.abc import Callable
from contextlib import suppress
from pathlib import Path
from types import ModuleType

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.core.io import atomic_output

#: Environment variable naming the cache folder (``off``: no cache).
CACHE_ENV = "SEMINSPECT_CACHE_DIR"
#: Environment variable bounding the cache folder's size, in megabytes.
CACHE_MAX_ENV = "SEMINSPECT_CACHE_MAX_MB"
#: The bound when ``CACHE_MAX_ENV`` is unset: a city world's grids take about 24 MB.
DEFAULT_CACHE_MAX_MB = 2048


def cache_dir() -> Path | None:
    """The cache folder, or None when the cache is off."""
    chosen = os.environ.get(CACHE_ENV)
    if chosen == "off":
        return None
    if chosen:
        return Path(chosen)
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "seminspect"


def cache_limit_bytes() -> int:
    """The most bytes the cache folder may hold (``CACHE_MAX_ENV``, else the default)."""
    chosen = os.environ.get(CACHE_MAX_ENV, "")
    try:
        megabytes = float(chosen) if chosen else DEFAULT_CACHE_MAX_MB
    except ValueError:
        megabytes = math.nan
    if not (math.isfinite(megabytes) and megabytes >= 0):
        raise InvalidInputError(
            f"{CACHE_MAX_ENV} must be a number of megabytes >= 0, not {chosen!r}"
        )
    return int(megabytes * 2**20)


def source_digest(*modules: ModuleType) -> str:
    """Hash of the modules' source files: a key part that changes whenever their code does."""
    digest = hashlib.blake2b(digest_size=16)
    for module in modules:
        digest.update(Path(str(module.__file__)).read_bytes())
    return digest.hexdigest()


def array_key(*parts: object) -> str:
    """Hash of arrays (dtype, shape and bytes) and other values (their ``repr``)."""
    digest = hashlib.blake2b(digest_size=20)
    for part in parts:
        if isinstance(part, np.ndarray):
            digest.update(f"{part.dtype.str}{part.shape}".encode())
            digest.update(np.ascontiguousarray(part).tobytes())
        else:
            digest.update(repr(part).encode())
        digest.update(b"\0")
    return digest.hexdigest()


def cached_array(kind: str, key: str, build: Callable[[], NDArray]) -> NDArray:
    """The array stored under ``kind/key``, or ``build()``'s result, stored for next time."""
    folder = cache_dir()
    if folder is None:
        return build()
    limit_bytes = cache_limit_bytes()  # a bad bound is an error before any work, hit or miss
    path = folder / kind / f"{key}.npy"
    try:
        array = np.load(path, allow_pickle=False)
        os.utime(path)  # a use: eviction goes by last use
        return array
    except (OSError, ValueError):  # absent, unreadable or torn by another writer's crash
        pass
    array = build()
    try:
        with atomic_output(path) as temporary:
            np.save(temporary, array, allow_pickle=False)
        evict_least_recent(folder, limit_bytes)
    except OSError:  # a read-only or full disk: the array is still good
        pass
    return array


def evict_least_recent(folder: Path, limit_bytes: int) -> list[Path]:
    """Delete the cache's least recently used files until the folder holds at most
    ``limit_bytes``; returns the files deleted."""
    entries = []
    for path in folder.rglob("*.npy"):
        with suppress(OSError):  # another process may delete it meanwhile
            stat = path.stat()
            entries.append((stat.st_mtime, stat.st_size, path))
    total = sum(size for _, size, _ in entries)
    deleted = []
    for _, size, path in sorted(entries, key=lambda entry: entry[0]):
        if total <= limit_bytes:
            break
        with suppress(OSError):
            path.unlink()
            deleted.append(path)
        total -= size
    return deleted
