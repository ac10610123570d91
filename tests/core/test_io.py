import errno
import json
import os
import stat
from pathlib import Path

import numpy as np
import pytest

from full_disk import fill_disk
from seminspect.core.errors import FileFormatError
from seminspect.core.io import (
    atomic_output,
    atomic_write_text,
    read_json,
    read_versioned_json,
    read_yaml,
    save_npz_atomic,
    write_versioned_json,
)


def test_versioned_round_trip(tmp_path: Path) -> None:
    path = write_versioned_json(tmp_path / "a" / "doc.json", "kind", 2, {"x": [1.5, 2]})
    doc = read_versioned_json(path, "kind", [1, 2])
    assert doc == {"format": "kind", "version": 2, "x": [1.5, 2]}


def test_written_files_get_ordinary_permissions(tmp_path: Path) -> None:
    path = atomic_write_text(tmp_path / "f.txt", "hello")
    mode = stat.S_IMODE(path.stat().st_mode)
    umask = os.umask(0)
    os.umask(umask)
    assert mode == 0o666 & ~umask


def test_failed_write_keeps_the_old_file(tmp_path: Path) -> None:
    path = atomic_write_text(tmp_path / "f.json", '{"ok": 1}')
    with pytest.raises(RuntimeError), atomic_output(path) as tmp:
        tmp.write_text("half a fi")
        raise RuntimeError("crash while writing")
    assert read_json(path) == {"ok": 1}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.json"]


def test_nan_is_refused_when_writing(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="JSON compliant"):
        write_versioned_json(tmp_path / "n.json", "kind", 1, {"x": float("nan")})
    assert not (tmp_path / "n.json").exists()


def test_npz_is_written_atomically(tmp_path: Path) -> None:
    save_npz_atomic(tmp_path / "a.npz", points=np.arange(6.0).reshape(2, 3))
    with np.load(tmp_path / "a.npz") as data:
        assert data["points"].shape == (2, 3)


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ('{"format": "kind", "version": 1, "x": [1, 2', "malformed JSON at line 1"),
        ("[1, 2]", "expected a JSON object"),
        ('{"format": "other", "version": 1}', "expected a 'kind' file"),
        ('{"format": "kind", "version": 9}', "version 9 is not supported"),
        ('{"format": "kind", "version": 1, "x": NaN}', "non-standard JSON constant NaN"),
        ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
    ],
)
def test_broken_documents_give_one_clear_error(tmp_path: Path, content: str, message: str) -> None:
    path = tmp_path / "doc.json"
    path.write_text(content)
    with pytest.raises(FileFormatError, match=message):
        read_versioned_json(path, "kind", [1])


def test_binary_missing_directory_and_oversized_files(tmp_path: Path) -> None:
    binary = tmp_path / "b.json"
    binary.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(FileFormatError, match="not UTF-8"):
        read_json(binary)
    with pytest.raises(FileFormatError, match="no such file"):
        read_json(tmp_path / "missing.json")
    with pytest.raises(FileFormatError, match="is a directory"):
        read_json(tmp_path)
    big = tmp_path / "big.json"
    big.write_text(json.dumps({"x": "y" * 2000}))
    with pytest.raises(FileFormatError, match="larger than"):
        read_json(big, max_bytes=1000)


def test_read_yaml_turns_every_broken_file_into_one_line(tmp_path) -> None:
    good = tmp_path / "grid.yaml"
    good.write_text("worlds: [city]\nseeds: [0, 1]\n", encoding="utf-8")
    assert read_yaml(good) == {"worlds": ["city"], "seeds": [0, 1]}
    bad = tmp_path / "bad.yaml"
    bad.write_text("worlds: [city\n", encoding="utf-8")
    with pytest.raises(FileFormatError, match="malformed YAML"):
        read_yaml(bad)
    with pytest.raises(FileFormatError, match="no such file"):
        read_yaml(tmp_path / "missing.yaml")


def _write_with_a_third_party_writer(path: Path) -> None:
    with atomic_output(path) as tmp:
        tmp.write_bytes(b"new")


@pytest.mark.parametrize(
    "write",
    [
        lambda path: atomic_write_text(path, "new"),
        lambda path: write_versioned_json(path, "kind", 1, {"x": 1}),
        lambda path: save_npz_atomic(path, a=np.zeros(3)),
        _write_with_a_third_party_writer,
    ],
    ids=["text", "versioned json", "npz", "third-party writer"],
)
def test_a_full_disk_names_the_file_and_keeps_the_old_one(tmp_path, monkeypatch, write) -> None:
    path = atomic_write_text(tmp_path / "out.npz", "old")
    fill_disk(monkeypatch, "out.npz")
    with pytest.raises(OSError, match="No space left") as raised:
        write(path)
    assert raised.value.errno == errno.ENOSPC and raised.value.filename == str(path)
    assert path.read_text() == "old" and sorted(tmp_path.iterdir()) == [path]  # no temporary


def test_a_third_party_writers_error_about_another_file_keeps_its_name(tmp_path) -> None:
    with pytest.raises(FileNotFoundError) as raised, atomic_output(tmp_path / "out.txt"):
        (tmp_path / "missing.txt").read_text()
    assert raised.value.filename == str(tmp_path / "missing.txt")


def test_a_file_rewritten_in_place_needs_no_room_for_a_copy(tmp_path, monkeypatch) -> None:
    from seminspect.core.io import rewrite_in_place

    path = atomic_write_text(tmp_path / "status.json", "running")
    fill_disk(monkeypatch)  # no room for a new file: its own blocks take the new bytes
    rewrite_in_place(path, b"failed")
    assert path.read_text() == "failed"
    fill_disk(monkeypatch, in_place=True)
    with pytest.raises(OSError, match="No space left") as raised:
        rewrite_in_place(path, b"again")
    assert raised.value.filename == str(path)


def test_file_sha256_matches_hashlib_over_blocks_larger_than_one_read(tmp_path) -> None:
    import hashlib

    from seminspect.core.io import file_sha256

    data = bytes(range(256)) * 5000  # 1.28 MB: more than one 1 MiB block
    target = tmp_path / "weights.bin"
    target.write_bytes(data)
    assert file_sha256(target) == hashlib.sha256(data).hexdigest()
    target.write_bytes(data[:-1])
    assert file_sha256(target) != hashlib.sha256(data).hexdigest()
