import io
import os
import threading
import time
import warnings
import zipfile

import numpy as np
import pytest

from seminspect.core import cache
from seminspect.core.cache import (
    CACHE_ENV,
    CacheWarning,
    array_key,
    cache_dir,
    cache_entries_used,
    cached_array,
    reset_cache_entries_used,
)
from seminspect.core.errors import InvalidInputError

K1, K2, K3 = (array_key(name) for name in ("k1", "k2", "k3"))


@pytest.fixture
def folder(tmp_path, monkeypatch):
    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "cache"))
    return tmp_path / "cache"


def counting_build(value: float, shape: tuple[int, ...] = (3, 4)):
    calls = []

    def build() -> np.ndarray:
        calls.append(1)
        return np.full(shape, value, dtype=np.float32)

    return build, calls


def entry_file(folder, key: str, kind: str = "grids"):
    """The one file holding ``key``'s entry, whatever the cache's naming of it."""
    (found,) = (folder / kind).glob(f"{key}*.npy")
    return found


def test_an_array_is_built_once_and_then_read_back(folder) -> None:
    build, calls = counting_build(2.5)
    first = cached_array("grids", K1, build)
    second = cached_array("grids", K1, build)
    assert len(calls) == 1
    assert second.dtype == np.float32
    np.testing.assert_array_equal(first, second)
    assert entry_file(folder, K1).name == f"{K1}.{array_key(first)}.npy"
    assert not [p for p in (folder / "grids").iterdir() if p.name.startswith(".")]


def test_another_key_builds_afresh(folder) -> None:
    build, calls = counting_build(1.0)
    cached_array("grids", K1, build)
    cached_array("grids", K2, build)
    assert len(calls) == 2


def _flip_bytes(path) -> None:
    data = bytearray(path.read_bytes())
    data[-20:-10] = bytes(b ^ 0xFF for b in data[-20:-10])  # inside the array's values
    path.write_bytes(bytes(data))


def _zip(path) -> None:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        archive.writestr("arr_0.npy", path.read_bytes())
    path.write_bytes(buffer.getvalue())


def _save(array: np.ndarray):
    return lambda path: np.save(path, array)


DAMAGES = {
    "flipped bytes": _flip_bytes,
    "empty": lambda path: path.write_bytes(b""),
    "truncated": lambda path: path.write_bytes(path.read_bytes()[:100]),
    "zip": _zip,
    "wrong shape": _save(np.zeros((4, 3), dtype=np.float32)),
    "wrong dtype": _save(np.zeros((3, 4), dtype=np.float64)),
    "pickle": lambda path: np.save(path, np.array([{"a": 1}], dtype=object), allow_pickle=True),
    "huge header": lambda path: path.write_bytes(  # a flipped digit: a 149 GiB shape
        path.read_bytes().replace(b"(3, 4), }" + b" " * 10, b"(9999999999, 4), } ")
    ),
    "not numpy": lambda path: path.write_bytes(b"\x93NUMPY not really"),
}


@pytest.mark.parametrize("damage", DAMAGES.values(), ids=DAMAGES.keys())
def test_a_damaged_entry_is_deleted_and_rebuilt_with_a_warning(folder, damage) -> None:
    build, calls = counting_build(3.0)
    cached_array("grids", K1, build)
    path = entry_file(folder, K1)
    damage(path)
    with pytest.warns(CacheWarning, match=str(path)) as caught:
        rebuilt = cached_array("grids", K1, build)
    assert len(caught) == 1 and "\n" not in str(caught[0].message)
    assert len(calls) == 2
    np.testing.assert_array_equal(rebuilt, np.full((3, 4), 3.0, dtype=np.float32))
    assert rebuilt.dtype == np.float32
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the replacement is sound: no warning, no build
        np.testing.assert_array_equal(cached_array("grids", K1, build), rebuilt)
    assert len(calls) == 2
    assert len(list((folder / "grids").iterdir())) == 1


def test_an_unreadable_folder_entry_named_like_ours_is_skipped(folder) -> None:
    build, calls = counting_build(3.0)
    (folder / "grids" / f"{K1}.{'0' * 40}.npy").mkdir(parents=True)  # not a file at all
    with pytest.warns(CacheWarning, match="damaged cache entry"):
        assert cached_array("grids", K1, build)[0, 0] == 3.0
    assert len(calls) == 1


def test_off_builds_every_time_and_writes_nothing(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv(CACHE_ENV, "off")
    assert cache_dir() is None
    build, calls = counting_build(1.0)
    reset_cache_entries_used()
    cached_array("grids", K1, build)
    cached_array("grids", K1, build)
    assert len(calls) == 2
    assert cache_entries_used() == []


def test_an_unwritable_cache_still_returns_the_array(tmp_path, monkeypatch) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv(CACHE_ENV, str(blocker))
    build, calls = counting_build(4.0)
    reset_cache_entries_used()
    assert cached_array("grids", K1, build)[0, 0] == 4.0
    assert cached_array("grids", K1, build)[0, 0] == 4.0
    assert len(calls) == 2  # nothing stored, nothing read
    outcomes = [entry["outcome"] for entry in cache_entries_used()]
    assert outcomes == ["not stored: Not a directory"] * 2


def test_default_folder_follows_xdg(monkeypatch, tmp_path) -> None:
    monkeypatch.delenv(CACHE_ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert cache_dir() == tmp_path / "seminspect"


@pytest.mark.parametrize(("kind", "key"), [("grids", "k1"), ("../up", K1), ("Grids", K1)])
def test_kinds_and_keys_outside_the_naming_scheme_are_refused(folder, kind, key) -> None:
    with pytest.raises(InvalidInputError, match="hex digest"):
        cached_array(kind, key, counting_build(1.0)[0])


def test_keys_change_with_any_input() -> None:
    a = np.arange(6, dtype=np.float64).reshape(2, 3)
    base = array_key("ground", a, 0.05, (0.15, 2.0))
    assert base == array_key("ground", a.copy(), 0.05, (0.15, 2.0))
    changed = a.copy()
    changed[1, 2] += 1e-9
    others = [
        array_key("aerial", a, 0.05, (0.15, 2.0)),
        array_key("ground", changed, 0.05, (0.15, 2.0)),
        array_key("ground", a.astype(np.float32), 0.05, (0.15, 2.0)),
        array_key("ground", a.reshape(3, 2), 0.05, (0.15, 2.0)),
        array_key("ground", a, 0.1, (0.15, 2.0)),
        array_key("ground", a, 0.05, (0.15, 2.5)),
    ]
    assert len({base, *others}) == 1 + len(others)


def test_source_digest_follows_the_code() -> None:
    assert cache.source_digest(cache) == cache.source_digest(cache)
    assert cache.source_digest(cache) != cache.source_digest(np)


def _age(path, seconds_ago: float) -> None:
    stamp = time.time() - seconds_ago
    os.utime(path, (stamp, stamp))


def test_the_least_recently_used_files_go_first_when_the_cache_is_full(folder) -> None:
    build, _ = counting_build(1.0)  # 3 x 4 float32: 176 bytes on disk with the .npy header
    for key in (K1, K2, K3):
        cached_array("grids", key, build)
    old, used, new = (entry_file(folder, key) for key in (K1, K2, K3))
    for age, path in enumerate((new, used, old)):
        _age(path, 1000 + 100 * age)
    cached_array("grids", K2, build)  # a read marks it as the most recent use
    size = new.stat().st_size
    deleted = cache.evict_least_recent(folder, 2 * size)
    assert deleted == [old]
    assert sorted((folder / "grids").iterdir()) == sorted([new, used])


def test_a_store_keeps_the_folder_under_its_bound(folder, monkeypatch) -> None:
    build, _ = counting_build(2.0)
    cached_array("grids", K1, build)
    first = entry_file(folder, K1)
    monkeypatch.setenv(cache.CACHE_MAX_ENV, str(1.5 * first.stat().st_size / 2**20))
    _age(first, 1000)
    cached_array("grids", K2, build)
    assert list((folder / "grids").iterdir()) == [entry_file(folder, K2)]


def test_eviction_leaves_files_the_cache_did_not_write(folder, monkeypatch) -> None:
    theirs = {
        "experiments/run-1.npy": np.arange(20_000.0),
        "experiments/run-2.npy": np.arange(30_000.0),
        "notes.npy": np.arange(10.0),
        "grids/mine.npy": np.ones(1000),  # in the cache's own kind folder
        f"grids/{K3}.npy.backup.npy": np.ones(5),
    }
    for name, array in theirs.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        np.save(folder / name, array)
        _age(folder / name, 10_000)  # older than any entry: first to go if eviction took them
    monkeypatch.setenv(cache.CACHE_MAX_ENV, str(300 / 2**20))  # room for one 3 x 4 entry
    build, _ = counting_build(1.0)
    for key in (K1, K2):
        cached_array("grids", key, build)
    for name, array in theirs.items():
        np.testing.assert_array_equal(np.load(folder / name), array)
    assert not list((folder / "grids").glob(f"{K1}*"))  # the older entry went
    assert entry_file(folder, K2).is_file()


def test_entries_of_earlier_versions_and_killed_stores_are_evicted(folder) -> None:
    build, _ = counting_build(1.0)
    cached_array("grids", K1, build)
    legacy = folder / "grids" / f"{K2}.npy"  # how the cache named entries before checksums
    np.save(legacy, np.ones(4))
    stale = folder / "grids" / f".{K3}.npy.x1y2z3ab.npy"
    stale.write_bytes(b"half a store, killed")
    for path in (legacy, stale):
        _age(path, 2 * 3600)
    deleted = cache.evict_least_recent(folder, entry_file(folder, K1).stat().st_size)
    assert sorted(deleted) == sorted([legacy, stale])


def test_eviction_spares_a_store_in_progress(folder) -> None:
    """Another process's temporary file, still being written, must survive eviction."""
    build, _ = counting_build(1.0)
    cached_array("grids", K1, build)
    in_progress = folder / "grids" / f".{K2}.{'a' * 40}.npy.k2x9q0zz.npy"
    in_progress.write_bytes(b"being written")
    cache.evict_least_recent(folder, 0)
    assert in_progress.is_file()
    assert not list((folder / "grids").glob(f"{K1}*"))  # the entry itself went


def test_two_writers_storing_at_once_under_a_small_bound(folder, monkeypatch) -> None:
    monkeypatch.setenv(cache.CACHE_MAX_ENV, str(0.2))  # three of the 64 KB entries
    keys = [array_key("writer", n) for n in range(24)]
    reset_cache_entries_used()
    results: dict[str, np.ndarray] = {}

    def store(share: list[str]) -> None:
        for n, key in enumerate(share):
            results[key] = cached_array("grids", key, counting_build(float(n), (128, 128))[0])

    writers = [threading.Thread(target=store, args=(keys[i::2],)) for i in range(2)]
    for writer in writers:
        writer.start()
    for writer in writers:
        writer.join()
    for i, key in enumerate(keys):
        np.testing.assert_array_equal(results[key], np.full((128, 128), float(i // 2)))
    used = cache_entries_used()
    assert sorted(entry["key"] for entry in used) == sorted(keys)
    assert {entry["outcome"] for entry in used} == {"stored"}
    assert sum(p.stat().st_size for p in (folder / "grids").iterdir()) <= 0.2 * 2**20


def test_the_entries_a_run_used_are_listed_with_their_outcome(folder) -> None:
    build, _ = counting_build(5.0)
    cached_array("grids", K1, build)
    reset_cache_entries_used()
    cached_array("grids", K1, build)
    cached_array("other", K2, build)
    path = entry_file(folder, K2, "other")
    path.write_bytes(b"")
    with pytest.warns(CacheWarning):
        cached_array("other", K2, build)
    used = cache_entries_used()
    assert [(entry["kind"], entry["key"]) for entry in used] == [
        ("grids", K1),
        ("other", K2),
        ("other", K2),
    ]
    assert used[0] == {
        "kind": "grids",
        "key": K1,
        "file": str(entry_file(folder, K1)),
        "outcome": "hit",
    }
    assert used[1]["outcome"] == "stored"
    assert used[2]["outcome"].startswith("rebuilt: unreadable")
    assert used[2]["file"] == str(path)
    used.clear()  # a copy: the record itself is untouched
    assert len(cache_entries_used()) == 3
    reset_cache_entries_used()
    assert cache_entries_used() == []


@pytest.mark.parametrize("value", ["lots", "-5", "nan", "inf"])
def test_an_impossible_bound_is_a_clear_error(monkeypatch, value) -> None:
    monkeypatch.setenv(cache.CACHE_MAX_ENV, value)
    with pytest.raises(InvalidInputError, match=cache.CACHE_MAX_ENV):
        cache.cache_limit_bytes()
