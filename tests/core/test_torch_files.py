"""Shared torch file checks: a damaged or foreign archive is one line; threads are restored."""

from __future__ import annotations

import zipfile
from pathlib import Path

import pytest

from seminspect.core.errors import FileFormatError
from seminspect.core.torch_files import check_archive, torch_threads


def test_a_damaged_member_fails_its_crc(tmp_path: Path) -> None:
    path = tmp_path / "weights.pt"
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_STORED) as archive:
        archive.writestr("data/0", b"0123456789" * 100)
    raw = bytearray(path.read_bytes())
    raw[raw.index(b"0123456789") + 5] ^= 0xFF  # one flipped byte inside the member
    path.write_bytes(bytes(raw))
    with pytest.raises(FileFormatError, match=r"data/0 fails its CRC check\); train again"):
        check_archive(path, "checkpoint", "train again")


def test_a_file_that_is_no_archive_is_not_readable(tmp_path: Path) -> None:
    path = tmp_path / "weights.pt"
    path.write_text("not a zip", encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"not a readable checkpoint \("):
        check_archive(path, "checkpoint", "train again")


def test_threads_are_set_inside_and_restored_after() -> None:
    torch = pytest.importorskip("torch")
    before = torch.get_num_threads()
    with torch_threads(1):
        assert torch.get_num_threads() == 1
    assert torch.get_num_threads() == before
