import os

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from seminspect.core.threads import (
    MAX_SENSOR_THREADS,
    THREADS_ENV,
    rotate_rows,
    sensor_threads,
    split_range,
)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_rotate_rows_is_bit_identical_to_the_threaded_product(dtype):
    rng = np.random.default_rng(3)
    rows = rng.normal(size=(50_000, 3)).astype(dtype)
    for quaternion in rng.normal(size=(5, 4)):
        rotation = Rotation.from_quat(quaternion).as_matrix().astype(dtype)
        assert np.array_equal(rotate_rows(rows, rotation), rows @ rotation.T)


def test_rotate_rows_into_a_reused_buffer_gives_the_same_numbers():
    rng = np.random.default_rng(4)
    rows = rng.normal(size=(20_000, 3)).astype(np.float32)
    buffer = np.full_like(rows, np.nan)
    for quaternion in rng.normal(size=(3, 4)):
        rotation = Rotation.from_quat(quaternion).as_matrix().astype(np.float32)
        written = rotate_rows(rows, rotation, out=buffer)
        assert written is buffer
        assert np.array_equal(buffer, rows @ rotation.T)


def test_rotate_rows_rotates():
    quarter_turn = Rotation.from_euler("z", 90, degrees=True).as_matrix()
    assert np.allclose(rotate_rows(np.array([[1.0, 0.0, 0.0]]), quarter_turn), [[0, 1, 0]])


def test_sensor_threads_keep_to_the_cores_and_the_settings(monkeypatch):
    monkeypatch.delenv(THREADS_ENV, raising=False)
    monkeypatch.delenv("OMP_NUM_THREADS", raising=False)
    cores = len(os.sched_getaffinity(0))
    assert sensor_threads() == min(MAX_SENSOR_THREADS, cores)
    monkeypatch.setenv("OMP_NUM_THREADS", "1")  # as Ray sets it for a one-CPU task
    assert sensor_threads() == 1
    monkeypatch.setenv(THREADS_ENV, "3")
    assert sensor_threads() == 3
    monkeypatch.setenv(THREADS_ENV, "none")  # not a count: ignored
    assert sensor_threads() == 1


def test_split_range_covers_the_range_in_order_or_keeps_it_whole():
    parts = split_range(10_000, 3, 1000)
    assert [p.start for p in parts] == [0, *(p.stop for p in parts[:-1])]
    assert parts[-1].stop == 10_000 and len(parts) == 3
    assert max(p.stop - p.start for p in parts) - min(p.stop - p.start for p in parts) <= 1
    assert split_range(1999, 2, 1000) == [slice(0, 1999)]  # under two threads' worth
    assert split_range(10_000, 1, 1000) == [slice(0, 10_000)]
