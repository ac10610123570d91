"""An on-disk cache of arrays that are slow to compute and fully determined by their inputs.

A world's collision grids take seconds to build and are rebuilt by every mission on the same
world; here they are stored once, under a key that hashes everything they are computed from,
and read back in milliseconds. A changed input gives another key, so a stale array is never
read: callers put into the key every input array and parameter, and the source of the code
that computes it (:func:`source_digest`).

The cache lives in ``$SEMINSPECT_CACHE_DIR``, else ``$XDG_CACHE_HOME/seminspect``, else
``~/.cache/seminspect``; ``SEMINSPECT_CACHE_DIR=off`` turns it off. An entry is the file
``<kind>/<key>.<checksum>.npy``, the checksum being :func:`array_key` of the array it holds.
Files are written atomically (``core.io``), so a reader sees a whole entry or none, and two
processes storing at once do not disturb each other. Every read is verified: an entry that
cannot be parsed or whose content no longer matches its checksum (a flipped byte, a truncated
or replaced file) is deleted and rebuilt with a :class:`CacheWarning`; a cache that cannot be
written only costs the rebuild. The folder is kept under ``$SEMINSPECT_CACHE_MAX_MB`` (default
2,048 MB): after each store the entries used least recently (a read counts as a use) are deleted
until it fits. Eviction deletes only files named as the cache names them (entries, entries of
earlier versions, temporaries of stores interrupted over an hour ago), never other files that
share the folder.

:func:`cache_entries_used` lists the entries read or written since
:func:`reset_cache_entries_used`, so a run can record which cached arrays it relied on.
"""

from __future__ import annotations

import hashlib
import math
import os
import re
import threading
import time
import warnings
from collections.abc import Callable, Iterator
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

_KIND = re.compile(r"[a-z][a-z0-9_-]{0,31}")
_KEY = re.compile(r"[0-9a-f]{16,128}")
#: ``<key>.<checksum>.npy``: the names this cache gives its entries.
_ENTRY = re.compile(r"(?P<key>[0-9a-f]{16,128})\.(?P<checksum>[0-9a-f]{40})\.npy")
#: Entries of versions before checksums: ``<40 hex digits>.npy``; never read, only evicted.
_LEGACY = re.compile(r"[0-9a-f]{40}\.npy")
#: ``core.io``'s temporaries of an entry: ``.<entry name>.<random>.npy``.
_TEMPORARY = re.compile(r"\.(?:[0-9a-f]{16,128}\.[0-9a-f]{40}|[0-9a-f]{40})\.npy\.\w+\.npy")
#: A temporary this old belongs to a store that was killed, not to one still writing.
_STALE_TEMPORARY_S = 3600.0


class CacheWarning(UserWarning):
    """A cache entry was damaged: it was deleted and its array is being rebuilt."""


class _DamagedEntryError(Exception):
    """An entry's file is not the array its name promises; the message says why."""


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


# ------------------------------------------------------------------------- entries used
_used: list[dict[str, str]] = []
_used_lock = threading.Lock()  # missions on threads share the process's record


def cache_entries_used() -> list[dict[str, str]]:
    """The entries read or written since :func:`reset_cache_entries_used` (or the process's
    start), in order: ``kind``, ``key``, ``file`` and ``outcome``.

    The outcome is ``hit`` (read back), ``stored`` (built and stored), ``rebuilt: <why>`` (a
    damaged entry was deleted and replaced) or ``not stored: <why>`` (built, but the folder
    cannot be written; after ``rebuilt: <why>; `` when an entry was damaged too). Nothing is
    recorded while the cache is off.
    """
    with _used_lock:
        return [dict(entry) for entry in _used]


def reset_cache_entries_used() -> None:
    """Start a new record for :func:`cache_entries_used` (a run calls this as it starts)."""
    with _used_lock:
        _used.clear()


def _record(kind: str, key: str, path: Path, outcome: str) -> None:
    with _used_lock:
        _used.append({"kind": kind, "key": key, "file": str(path), "outcome": outcome})


# ------------------------------------------------------------------------- reading, storing
def cached_array(kind: str, key: str, build: Callable[[], NDArray]) -> NDArray:
    """The array stored under ``kind/key``, or ``build()``'s result, stored for next time.

    ``kind`` is a short lower-case name (a folder), ``key`` a hexadecimal hash of the inputs
    (:func:`array_key`).
    """
    if not (_KIND.fullmatch(kind) and _KEY.fullmatch(key)):
        raise InvalidInputError(
            f"cache kind must be a short lower-case name and key a hex digest, got {kind!r}, "
            f"{key!r}"
        )
    folder = cache_dir()
    if folder is None:
        return build()
    limit_bytes = cache_limit_bytes()  # a bad bound is an error before any work, hit or miss
    found, damage = _read_entry(folder / kind, key)
    if found is not None:
        path, array = found
        _record(kind, key, path, "hit")
        return array
    array = build()
    path = folder / kind / f"{key}.{array_key(array)}.npy"
    outcome = f"rebuilt: {damage}" if damage else "stored"
    try:
        with atomic_output(path) as temporary:
            np.save(temporary, array, allow_pickle=False)
        evict_least_recent(folder, limit_bytes)
    except OSError as exc:  # a read-only or full disk: the array is still good
        failure = f"not stored: {exc.strerror or exc}"
        outcome = f"{outcome}; {failure}" if damage else failure
    _record(kind, key, path, outcome)
    return array


def _read_entry(folder: Path, key: str) -> tuple[tuple[Path, NDArray] | None, str]:
    """The verified entry of ``key`` in ``folder`` (or None), and why the entries found were
    damaged ("" when none was); damaged ones are deleted with a :class:`CacheWarning`."""
    damage = ""
    try:
        candidates = sorted(folder.glob(f"{key}.*.npy"))
    except OSError:  # an unreadable folder is a miss
        candidates = []
    for path in candidates:
        match = _ENTRY.fullmatch(path.name)
        if match is None:  # not a name the cache gives
            continue
        try:
            array = _load_verified(path, match["checksum"])
        except FileNotFoundError:  # evicted by another process since the listing: a miss
            continue
        except _DamagedEntryError as exc:
            damage = str(exc)
            warnings.warn(
                f"{path}: damaged cache entry ({damage}); deleted, rebuilding it",
                CacheWarning,
                stacklevel=3,
            )
            with suppress(OSError):
                path.unlink()
            continue
        with suppress(OSError):  # another process may have evicted it meanwhile
            os.utime(path)  # a use: eviction goes by last use
        return (path, array), damage
    return None, damage


def _load_verified(path: Path, checksum: str) -> NDArray:
    """The array in ``path``; :class:`_DamagedEntryError` if the file is not a plain ``.npy``
    array whose content hashes to ``checksum``."""
    try:
        with path.open("rb") as handle:
            array = np.lib.format.read_array(handle, allow_pickle=False)
    except FileNotFoundError:
        raise
    # Any failure to parse means a damaged file, and numpy raises many kinds: ValueError (bad
    # magic, header or size, a pickle or a zip), EOFError, OSError, MemoryError from a header
    # whose shape a flipped byte made huge, TypeError from a mangled dtype.
    except Exception as exc:
        first_line = (str(exc).splitlines() or [""])[0][:120]
        raise _DamagedEntryError(f"unreadable: {type(exc).__name__}: {first_line}") from None
    if array_key(array) != checksum:
        raise _DamagedEntryError(
            f"its {array.dtype} array of shape {array.shape} does not match its checksum"
        )
    return array


# ------------------------------------------------------------------------- eviction
def evict_least_recent(folder: Path, limit_bytes: int) -> list[Path]:
    """Delete the cache's least recently used files until the folder holds at most
    ``limit_bytes`` of them; returns the files deleted. Only the cache's own files count and
    go: other files in the folder are left alone."""
    entries = []
    for path in _own_files(folder):
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


def _own_files(folder: Path) -> Iterator[Path]:
    """The files the cache wrote in ``folder``: entries and entries of earlier versions in
    ``<kind>/`` folders, and temporaries of stores killed over an hour ago (a younger one may be
    another process's store in progress)."""
    stale_before = time.time() - _STALE_TEMPORARY_S
    with suppress(OSError):
        for kind in folder.iterdir():
            if not (_KIND.fullmatch(kind.name) and kind.is_dir()):
                continue
            for path in kind.iterdir():
                if _ENTRY.fullmatch(path.name) or _LEGACY.fullmatch(path.name):
                    yield path
                elif _TEMPORARY.fullmatch(path.name):
                    with suppress(OSError):
                        if path.stat().st_mtime < stale_before:
                            yield path
