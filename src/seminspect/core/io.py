"""Atomic file writes and versioned JSON documents.

Every file seminspect writes goes through :func:`atomic_write_bytes`: the data lands in a
temporary file in the same directory, is flushed to disk and then renamed over the target, so a
crash or Ctrl-C leaves either the old file or the new one, never a torn one. An ``OSError`` while
writing (a full disk) names the target, where the system names the temporary file or no file.

Versioned JSON documents carry a small envelope ``{"format": KIND, "version": N, ...}`` so that a
reader can refuse a file of another kind or a version it does not understand with a clear message.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import math
import os
import tempfile
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from seminspect.core.errors import FileFormatError

#: Refuse JSON documents larger than this; a scene graph of 10,000 inspected targets is ~200 MB.
MAX_JSON_BYTES = 1 << 30


def _file_mode() -> int:
    """Permissions a plainly created file would get (temporary files are created 0600)."""
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


_FILE_MODE = _file_mode()


def _temporary_beside(target: Path, suffix: str) -> tuple[int, str]:
    """A new temporary file in ``target``'s folder; an error names ``target``, not the temporary."""
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        return tempfile.mkstemp(prefix=f".{target.name}.", suffix=suffix, dir=target.parent)
    except OSError as exc:
        raise OSError(exc.errno, exc.strerror, str(target)) from None


@contextlib.contextmanager
def _naming(target: Path, temporary: str | None = None) -> Iterator[None]:
    """An ``OSError`` writing ``target`` names it: a failed ``write`` names no file, and the
    temporary file beside ``target`` means nothing to the user (another file's error stays)."""
    try:
        yield
    except OSError as exc:
        named = None if exc.filename is None else os.fsdecode(exc.filename)
        if exc.errno is None or named not in (None, temporary):
            raise
        raise OSError(exc.errno, exc.strerror, str(target)) from None


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically (temporary file + fsync + rename)."""
    target = Path(path)
    fd, tmp_name = _temporary_beside(target, ".tmp")
    try:
        with _naming(target, tmp_name):
            os.fchmod(fd, _FILE_MODE)
            with os.fdopen(fd, "wb") as handle:
                handle.write(data)
                handle.flush()
                os.fsync(handle.fileno())
            Path(tmp_name).replace(target)
    except BaseException:
        Path(tmp_name).unlink(missing_ok=True)
        raise
    return target


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` for a third-party writer; rename it over ``path``
    only when the block succeeds (the temporary file is removed otherwise)."""
    target = Path(path)
    fd, tmp_name = _temporary_beside(target, target.suffix)
    os.fchmod(fd, _FILE_MODE)
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        with _naming(target, tmp_name):
            yield tmp
            with tmp.open("rb+") as handle:
                os.fsync(handle.fileno())
            tmp.replace(target)
    finally:
        tmp.unlink(missing_ok=True)


def rewrite_in_place(path: str | os.PathLike[str], data: bytes) -> Path:
    """Overwrite the existing file ``path`` with ``data`` in its own blocks, then cut it to size.

    A last resort where :func:`atomic_write_bytes` fails for want of space: no second copy is
    needed, so new bytes no longer than the old blocks always fit. A crash midway, or bytes that
    need a block more on a full disk, leave the file torn.
    """
    target = Path(path)
    with _naming(target), target.open("r+b") as handle:
        handle.write(data)
        handle.truncate()
        handle.flush()
        os.fsync(handle.fileno())
    return target


def atomic_write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Write UTF-8 ``text`` to ``path`` atomically."""
    return atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_with(path: str | os.PathLike[str], write: Callable[[io.BytesIO], Any]) -> Path:
    """Atomically write whatever ``write(buffer)`` puts into an in-memory buffer (figures, npz)."""
    buffer = io.BytesIO()
    write(buffer)
    return atomic_write_bytes(path, buffer.getvalue())


def save_npz_atomic(path: str | os.PathLike[str], **arrays: np.ndarray) -> Path:
    """``numpy.savez_compressed`` with an atomic rename."""
    # numpy's stub lets ``**arrays`` meet the ``allow_pickle: bool`` keyword
    save = np.savez_compressed
    return atomic_write_with(path, lambda buf: save(buf, **arrays))  # type: ignore[arg-type]


def _json_default(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"cannot serialise {type(value).__name__} to JSON")


def dumps_json(document: Any, indent: int | None = None) -> str:
    """Serialise to strict JSON (NaN and infinity are refused: they are not JSON)."""
    return json.dumps(document, default=_json_default, indent=indent, allow_nan=False)


def write_versioned_json(
    path: str | os.PathLike[str],
    kind: str,
    version: int,
    payload: dict[str, Any],
    indent: int | None = None,
) -> Path:
    """Atomically write ``payload`` inside a ``{"format", "version"}`` envelope."""
    return atomic_write_text(path, versioned_json_text(kind, version, payload, indent))


def versioned_json_text(
    kind: str, version: int, payload: dict[str, Any], indent: int | None = None
) -> str:
    """The text :func:`write_versioned_json` writes, for a writer of its own."""
    return dumps_json({"format": kind, "version": version, **payload}, indent=indent) + "\n"


def _reject_constant(token: str) -> float:
    raise ValueError(f"non-standard JSON constant {token}")


def read_json(path: str | os.PathLike[str], max_bytes: int = MAX_JSON_BYTES) -> Any:
    """Read a JSON file, turning every way it can be broken into a :class:`FileFormatError`."""
    source = Path(path)
    try:
        size = source.stat().st_size
    except FileNotFoundError:
        raise FileFormatError(f"{source}: no such file") from None
    except OSError as exc:
        raise FileFormatError(f"{source}: cannot read ({exc.strerror})") from None
    if source.is_dir():
        raise FileFormatError(f"{source}: is a directory, expected a JSON file")
    if size > max_bytes:
        raise FileFormatError(f"{source}: {size} bytes is larger than the {max_bytes}-byte limit")
    try:
        text = source.read_text(encoding="utf-8")
        return json.loads(text, parse_constant=_reject_constant)
    except UnicodeDecodeError:
        raise FileFormatError(f"{source}: not UTF-8 text (is it a binary file?)") from None
    except json.JSONDecodeError as exc:
        raise FileFormatError(
            f"{source}: malformed JSON at line {exc.lineno} column {exc.colno}: {exc.msg}"
        ) from None
    except RecursionError:
        raise FileFormatError(f"{source}: JSON nested too deeply") from None
    except ValueError as exc:
        raise FileFormatError(f"{source}: {exc}") from None
    except OSError as exc:
        raise FileFormatError(f"{source}: cannot read ({exc.strerror})") from None


def read_versioned_json(
    path: str | os.PathLike[str],
    kind: str,
    versions: Iterable[int],
    max_bytes: int = MAX_JSON_BYTES,
) -> dict[str, Any]:
    """Read a document written by :func:`write_versioned_json`, checking its kind and version."""
    supported = sorted(set(versions))
    document = read_json(path, max_bytes)
    if not isinstance(document, dict):
        raise FileFormatError(f"{path}: expected a JSON object, found {type(document).__name__}")
    found_kind = document.get("format")
    if found_kind != kind:
        raise FileFormatError(f"{path}: expected a {kind!r} file, found format {found_kind!r}")
    found_version = document.get("version")
    # exact integers only: ``True == 1`` and ``1.0 == 1`` in Python, and neither is a version
    if type(found_version) is not int or found_version not in supported:
        raise FileFormatError(
            f"{path}: {kind} version {found_version!r} is not supported (supported: {supported})"
        )
    return document


def finite_or_none(value: float) -> float | None:
    """Map NaN and infinity to ``None`` for JSON output."""
    return value if math.isfinite(value) else None


def read_yaml(path: str | os.PathLike[str]) -> Any:
    """Read a YAML file (safe loader); any way it can be broken is a :class:`FileFormatError`."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise FileFormatError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise FileFormatError(f"{path}: cannot read ({exc})") from None
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise FileFormatError(f"{path}: malformed YAML: {str(exc).splitlines()[0]}") from None


def file_sha256(path: str | os.PathLike[str]) -> str:
    """Hex SHA-256 of a file's bytes, read in blocks (e.g. the checkpoint an evaluation used)."""
    digest = hashlib.sha256()
    with Path(path).open("rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()
