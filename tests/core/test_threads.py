import os
import threading
import time

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from seminspect.core.errors import InvalidInputError
from seminspect.core.threads import (
    MAX_SENSOR_THREADS,
    THREADS_ENV,
    blocks_of,
    rotate_rows,
    run_dealt,
    sensor_threads,
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


@pytest.mark.parametrize("threads", [2, 3])
def test_rotate_rows_dealt_to_threads_gives_the_same_numbers(threads):
    rng = np.random.default_rng(5)
    rows = rng.normal(size=(307_201, 3)).astype(np.float32)  # a frame's rays, and one more
    buffer = np.full_like(rows, np.nan)
    for quaternion in rng.normal(size=(3, 4)):
        rotation = Rotation.from_quat(quaternion).as_matrix().astype(np.float32)
        expected = rotate_rows(rows, rotation)
        assert np.array_equal(rotate_rows(rows, rotation, threads=threads), expected)
        assert rotate_rows(rows, rotation, out=buffer, threads=threads) is buffer
        assert np.array_equal(buffer, expected)


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
    monkeypatch.setenv("OMP_NUM_THREADS", "many")  # another library's setting: passed over
    monkeypatch.delenv(THREADS_ENV)
    assert sensor_threads() == min(MAX_SENSOR_THREADS, cores)


@pytest.mark.parametrize("setting", ["none", "0", "-2", "1.5"])
def test_an_unusable_thread_count_is_refused_in_one_line(monkeypatch, setting):
    monkeypatch.setenv(THREADS_ENV, setting)
    with pytest.raises(InvalidInputError, match=f"{THREADS_ENV} must be a whole number"):
        sensor_threads()


def test_blocks_of_cover_the_range_once_in_nearly_equal_blocks():
    blocks = blocks_of(10_000, 3, 1000, blocks_per_thread=4)
    assert len(blocks) == 12
    assert [b.start for b in blocks] == [0, *(b.stop for b in blocks[:-1])]
    assert blocks[-1].stop == 10_000
    assert max(b.stop - b.start for b in blocks) - min(b.stop - b.start for b in blocks) <= 1


def test_blocks_of_keep_small_or_single_threaded_work_whole():
    assert blocks_of(1999, 2, 1000) == [slice(0, 1999)]  # under two threads' worth
    assert blocks_of(10_000, 1, 1000) == [slice(0, 10_000)]


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_run_dealt_does_every_item_once(threads):
    done = np.zeros(50_000, dtype=np.int64)

    def work(block: slice) -> None:
        done[block] += 1

    run_dealt(work, len(done), threads, 1000)
    assert np.all(done == 1)


def test_a_thread_held_up_takes_fewer_blocks():
    """The caller's first block stalls; the pool worker takes every other block."""
    caller = threading.get_ident()
    taken: dict[int, int] = {}
    held: list[int] = []
    release = threading.Event()

    def work(block: slice) -> None:
        taken[block.start] = threading.get_ident()
        if threading.get_ident() == caller and not held:
            held.append(block.start)
            release.wait(timeout=5)  # until the other thread has done the rest
        elif len(taken) == 16:
            release.set()

    run_dealt(work, 16_000, 2, 1000)
    assert len(taken) == 16
    assert [start for start, thread in taken.items() if thread == caller] == held


def test_a_failing_block_fails_the_batch_after_the_other_thread_stopped():
    running = threading.Event()
    finished = []

    def work(block: slice) -> None:
        if threading.get_ident() != caller:
            running.set()
            time.sleep(0.05)
            finished.append(block.start)
        elif running.wait(timeout=5):
            raise RuntimeError("bad block")

    caller = threading.get_ident()
    with pytest.raises(RuntimeError, match="bad block"):
        run_dealt(work, 16_000, 2, 1000)
    done = len(finished)
    time.sleep(0.2)
    assert done >= 1 and len(finished) == done  # nothing ran on after the batch failed
