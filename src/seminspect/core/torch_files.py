"""What every torch user of seminspect shares (the 004 policy, the learned detector): a bounded
thread count, and ``torch.save`` archives checked before ``torch.load`` reads them.

``torch.load`` does not check the CRCs of an archive's members, so damaged weights would load
as other numbers; :func:`check_archive` refuses them first. torch itself is imported only where
a function needs it (it is an optional extra).
"""

from __future__ import annotations

import contextlib
import zipfile
import zlib
from collections.abc import Iterator
from pathlib import Path

from seminspect.core.errors import FileFormatError


def check_archive(source: Path, kind: str, remedy: str) -> None:
    """Refuse a ``torch.save`` archive with a member whose bytes no longer match their CRC."""
    try:
        with zipfile.ZipFile(source) as archive:
            damaged = archive.testzip()
    except (zipfile.BadZipFile, zlib.error, EOFError, NotImplementedError) as exc:
        raise unreadable(source, kind, exc) from None
    if damaged is not None:
        raise FileFormatError(f"{source}: damaged {kind} ({damaged} fails its CRC check); {remedy}")


def unreadable(source: Path, kind: str, exc: Exception) -> FileFormatError:
    """The one-line error of a file ``torch.load`` could not read."""
    first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return FileFormatError(f"{source}: not a readable {kind} ({first})")


@contextlib.contextmanager
def torch_threads(count: int) -> Iterator[None]:
    """torch's intra-op threads set to ``count`` inside the block, restored after it."""
    import torch  # noqa: PLC0415 - the optional extra, loaded when used

    threads = torch.get_num_threads()
    torch.set_num_threads(count)
    try:
        yield
    finally:
        torch.set_num_threads(threads)
