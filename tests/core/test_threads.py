import os
import threading

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from seminspect.core.errors import InvalidInputError
from seminspect.core.threads import (
    MAX_SENSOR_THREADS,
    THREADS_ENV,
    deal_range,
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


def test_deal_range_covers_the_range_once_in_blocks_dealt_in_turn():
    hands = deal_range(10_000, 3, 1000, blocks_per_thread=4)
    assert len(hands) == 3 and all(len(hand) == 4 for hand in hands)
    blocks = sorted((block for hand in hands for block in hand), key=lambda b: b.start)
    assert [b.start for b in blocks] == [0, *(b.stop for b in blocks[:-1])]
    assert blocks[-1].stop == 10_000
    assert max(b.stop - b.start for b in blocks) - min(b.stop - b.start for b in blocks) <= 1
    # Dealt in turn: a thread's blocks are every third one, so each gets a share of every region.
    assert [b.start for b in hands[1]] == [b.start for b in blocks[1::3]]


def test_deal_range_keeps_small_or_single_threaded_work_whole():
    assert deal_range(1999, 2, 1000) == [[slice(0, 1999)]]  # under two threads' worth
    assert deal_range(10_000, 1, 1000) == [[slice(0, 10_000)]]


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_run_dealt_does_every_item_once_the_caller_its_own_hand(threads):
    done = np.zeros(50_000, dtype=np.int64)
    workers: dict[int, int] = {}

    def work(block: slice) -> None:
        workers[block.start] = threading.get_ident()
        done[block] += 1

    run_dealt(work, len(done), threads, 1000)
    assert np.all(done == 1)
    mine = {start for start, worker in workers.items() if worker == threading.get_ident()}
    assert mine == {block.start for block in deal_range(len(done), threads, 1000)[0]}
