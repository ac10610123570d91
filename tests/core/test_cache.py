import os

import numpy as np
import pytest

from seminspect.core import cache
from seminspect.core.cache import CACHE_ENV, array_key, cache_dir, cached_array
from seminspect.core.errors import InvalidInputError


@pytest.fixture
def folder(tmp_path, monkeypatch):
    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "cache"))
    return tmp_path / "cache"


def counting_build(value: float):
    calls = []

    def build() -> np.ndarray:
        calls.append(1)
        return np.full((3, 4), value, dtype=np.float32)

    return build, calls


def test_an_array_is_built_once_and_then_read_back(folder) -> None:
    build, calls = counting_build(2.5)
    first = cached_array("grids", "k1", build)
    second = cached_array("grids", "k1", build)
    assert len(calls) == 1
    assert second.dtype == np.float32
    np.testing.assert_array_equal(first, second)
    assert (folder / "grids" / "k1.npy").is_file()
    assert not [p for p in (folder / "grids").iterdir() if p.name.startswith(".")]


def test_another_key_builds_afresh(folder) -> None:
    build, calls = counting_build(1.0)
    cached_array("grids", "k1", build)
    cached_array("grids", "k2", build)
    assert len(calls) == 2


def test_a_torn_file_is_rebuilt_and_replaced(folder) -> None:
    (folder / "grids").mkdir(parents=True)
    (folder / "grids" / "k1.npy").write_bytes(b"\x93NUMPY not really")
    build, calls = counting_build(3.0)
    assert cached_array("grids", "k1", build)[0, 0] == 3.0
    assert cached_array("grids", "k1", build)[0, 0] == 3.0
    assert len(calls) == 1


def test_off_builds_every_time_and_writes_nothing(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv(CACHE_ENV, "off")
    assert cache_dir() is None
    build, calls = counting_build(1.0)
    cached_array("grids", "k1", build)
    cached_array("grids", "k1", build)
    assert len(calls) == 2


def test_an_unwritable_cache_still_returns_the_array(tmp_path, monkeypatch) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv(CACHE_ENV, str(blocker))
    build, calls = counting_build(4.0)
    assert cached_array("grids", "k1", build)[0, 0] == 4.0
    assert cached_array("grids", "k1", build)[0, 0] == 4.0
    assert len(calls) == 2  # nothing stored, nothing read


def test_default_folder_follows_xdg(monkeypatch, tmp_path) -> None:
    monkeypatch.delenv(CACHE_ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert cache_dir() == tmp_path / "seminspect"


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


def test_the_least_recently_used_files_go_first_when_the_cache_is_full(folder) -> None:
    build, _ = counting_build(1.0)  # 3 x 4 float32: 176 bytes on disk with the .npy header
    for key in ("old", "used", "new"):
        cached_array("grids", key, build)
    grids = folder / "grids"
    for age, key in enumerate(("new", "used", "old")):
        stamp = 1_000_000 - 100 * age
        os.utime(grids / f"{key}.npy", (stamp, stamp))
    cached_array("grids", "used", build)  # a read marks it as the most recent use
    size = (grids / "new.npy").stat().st_size
    deleted = cache.evict_least_recent(folder, 2 * size)
    assert deleted == [grids / "old.npy"]
    assert sorted(p.name for p in grids.iterdir()) == ["new.npy", "used.npy"]


def test_a_store_keeps_the_folder_under_its_bound(folder, monkeypatch) -> None:
    build, _ = counting_build(2.0)
    cached_array("grids", "first", build)
    size = (folder / "grids" / "first.npy").stat().st_size
    monkeypatch.setenv(cache.CACHE_MAX_ENV, str(1.5 * size / 2**20))
    os.utime(folder / "grids" / "first.npy", (1_000_000, 1_000_000))
    cached_array("grids", "second", build)
    assert [p.name for p in (folder / "grids").iterdir()] == ["second.npy"]


@pytest.mark.parametrize("value", ["lots", "-5", "nan", "inf"])
def test_an_impossible_bound_is_a_clear_error(monkeypatch, value) -> None:
    monkeypatch.setenv(cache.CACHE_MAX_ENV, value)
    with pytest.raises(InvalidInputError, match=cache.CACHE_MAX_ENV):
        cache.cache_limit_bytes()
