"""The threads of a mission: how many its sensors use, how work is dealt out to them, the
one-thread workers that run in the background, and small matrix products on one BLAS thread.

Rotating a frame's rays is a ``(N, 3) @ (3, 3)`` product: far too little work per row for
OpenBLAS to gain from its threads, yet it wakes them for every call, and on a busy machine the
hand-over alone can cost many times the product (docs/benchmarks.md, "Missions at 50x real
time"). One thread computes every row with the same kernel, so the result is bit-for-bit the
multi-threaded one (``tests/core/test_threads.py``); dealt out in blocks to the sensors'
threads (:func:`run_dealt`), each row is still computed by that kernel.
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from functools import cache

import numpy as np
from numpy.typing import NDArray
from threadpoolctl import ThreadpoolController

from seminspect.core.errors import InvalidInputError


@cache
def _controller() -> ThreadpoolController:
    # Inspecting the loaded libraries takes milliseconds: do it once per process.
    return ThreadpoolController()


def rotate_rows(
    vectors: NDArray, rotation: NDArray, out: NDArray | None = None, threads: int = 1
) -> NDArray:
    """``vectors @ rotation.T`` (``(N, 3)`` rows by a ``(3, 3)`` matrix) on one BLAS thread.

    ``out``, when given, is an ``(N, 3)`` array of the product's dtype that receives the rows
    (a buffer reused between calls saves the allocation; the numbers are the same). With
    ``threads`` > 1 blocks of rows are dealt out to that many threads (:func:`run_dealt`),
    each row computed by the same kernel, so again the same numbers.
    """
    rows, turn = np.asarray(vectors), np.asarray(rotation).T
    with _controller().limit(limits=1, user_api="blas"):
        if threads <= 1:
            return np.matmul(rows, turn, out=out)
        product = np.empty(rows.shape, np.result_type(rows, turn)) if out is None else out

        def rotate(block: slice) -> None:
            np.matmul(rows[block], turn, out=product[block])

        run_dealt(rotate, len(rows), threads, MIN_ROWS_PER_THREAD)
        return product


#: Below this many rows per thread, dealing a rotation out costs more than it saves.
MIN_ROWS_PER_THREAD = 16_384


#: Environment variable that sets :func:`sensor_threads`.
THREADS_ENV = "SEMINSPECT_THREADS"
#: Ray casting gains little beyond this many threads per mission.
MAX_SENSOR_THREADS = 2


def sensor_threads() -> int:
    """Threads one mission's ray casting may use.

    ``$SEMINSPECT_THREADS`` when set; otherwise the cores this process may run on, at most
    :data:`MAX_SENSOR_THREADS` and at most ``$OMP_NUM_THREADS`` (which Ray sets to a task's
    CPUs, so the missions of a sweep keep to one thread each). Results never depend on it:
    every ray is cast on its own, whichever thread casts it.

    Raises:
        InvalidInputError: ``$SEMINSPECT_THREADS`` is set but not a whole number >= 1 (an
            unusable ``$OMP_NUM_THREADS`` belongs to other libraries and is passed over).
    """
    chosen = os.environ.get(THREADS_ENV, "").strip()
    if chosen:
        if _positive(chosen) is None:
            raise InvalidInputError(
                f"{THREADS_ENV} must be a whole number of threads >= 1, got {chosen!r}"
            )
        return int(chosen)
    cores = min(MAX_SENSOR_THREADS, len(os.sched_getaffinity(0)))
    return min(cores, _positive(os.environ.get("OMP_NUM_THREADS", "")) or cores)


def _positive(value: str) -> int | None:
    value = value.strip()
    return int(value) if value.isdigit() and int(value) >= 1 else None


@cache
def thread_pool(threads: int) -> ThreadPoolExecutor:
    """One pool of ``threads`` workers per process, shared by the compiled loops that release
    the GIL (ray casting, shading) and the camera noise drawn ahead, so a mission starts its
    threads once."""
    return ThreadPoolExecutor(threads, thread_name_prefix="seminspect")


@cache
def serial_worker(purpose: str) -> ThreadPoolExecutor:
    """One worker thread per process and ``purpose`` (``"map"``, ``"images"``): what is handed
    to it runs one item at a time, in the order it was handed over."""
    return ThreadPoolExecutor(1, thread_name_prefix=f"seminspect-{purpose}")


#: Blocks per thread when a batch is dealt out: enough that the threads end together, few
#: enough that a block's call overhead stays negligible.
BLOCKS_PER_THREAD = 8


def blocks_of(
    count: int, threads: int, min_per_thread: int, blocks_per_thread: int = BLOCKS_PER_THREAD
) -> list[slice]:
    """``range(count)`` cut into ``threads * blocks_per_thread`` contiguous blocks of nearly
    equal size, in order; one block when a thread would get fewer than ``min_per_thread`` items
    (below that, splitting costs more than it saves)."""
    if not worth_splitting(count, threads, min_per_thread):
        return [slice(0, count)]
    blocks = threads * blocks_per_thread
    return [slice(count * i // blocks, count * (i + 1) // blocks) for i in range(blocks)]


def worth_splitting(count: int, threads: int, min_per_thread: int) -> bool:
    """Whether :func:`blocks_of` cuts ``count`` items into more than one block."""
    return threads > 1 and count >= 2 * min_per_thread


def run_dealt(
    work: Callable[[slice], object], count: int, threads: int, min_per_thread: int
) -> None:
    """Call ``work`` on every block of :func:`blocks_of`, the calling thread and ``threads - 1``
    pool workers each taking the next block not yet taken until none is left. For work whose
    result does not depend on the split (each item on its own) and that releases the GIL.

    Taking blocks as each thread comes free balances the threads however the work is spread: a
    camera's top rows (sky, far walls) cast in about half the time of its bottom rows, and a
    LiDAR's rings differ the same way; and a thread the system pauses for a while (the map's
    walks and the noise drawn ahead share the cores) or a pool worker slow to wake simply
    takes fewer blocks (docs/benchmarks.md).
    """
    blocks = blocks_of(count, threads, min_per_thread)
    if len(blocks) == 1:
        work(blocks[0])
        return
    claim = itertools.count()  # next() on it is atomic under the GIL

    def work_through() -> None:
        while (taken := next(claim)) < len(blocks):
            work(blocks[taken])

    others = [thread_pool(threads).submit(work_through) for _ in range(threads - 1)]
    try:
        work_through()
    finally:
        # Nothing may still write into the caller's arrays once this returns or raises; a
        # worker that has not started would find nothing left, so it is not waited for.
        for other in others:
            if not other.cancel():
                other.result()
