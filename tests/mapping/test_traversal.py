"""The allocation-free ray walk against the array-based walk it replaced, cell for cell,
and walks that start part way along their rays (thinned carving)."""

import math

import numpy as np
import pytest

from seminspect.mapping.traversal import (
    FREE,
    MIN_RAYS_PER_THREAD,
    OCCUPIED,
    integrate_rays_kernel,
)


def _reference_clip(o, d, shape) -> tuple[float, float]:
    t0, t1 = 0.0, 1.0
    for k in range(3):
        if d[k] == 0.0:
            if o[k] < 0.0 or o[k] >= shape[k]:
                return 1.0, 0.0
            continue
        ta, tb = (0.0 - o[k]) / d[k], (shape[k] - o[k]) / d[k]
        t0, t1 = max(t0, min(ta, tb)), min(t1, max(ta, tb))
    return t0, t1


def _reference_walk(states, o, d, hit) -> None:
    """The previous walk (per-ray state in small arrays), in plain Python: the oracle."""
    shape = states.shape
    t0, t1 = _reference_clip(o, d, shape)
    if t0 > t1:
        return
    cell = [min(max(math.floor(o[k] + t0 * d[k]), 0), shape[k] - 1) for k in range(3)]
    last = [min(max(math.floor(o[k] + t1 * d[k]), 0), shape[k] - 1) for k in range(3)]
    step, t_max, t_delta = [0] * 3, [math.inf] * 3, [math.inf] * 3
    for k in range(3):
        if d[k] > 0:
            step[k], t_max[k], t_delta[k] = 1, (cell[k] + 1 - o[k]) / d[k], 1.0 / d[k]
        elif d[k] < 0:
            step[k], t_max[k], t_delta[k] = -1, (cell[k] - o[k]) / d[k], -1.0 / d[k]
    occupy_end = hit and all(0.0 <= o[k] + d[k] < shape[k] for k in range(3))

    def mark(index, value) -> None:
        if states[tuple(index)] != OCCUPIED:
            states[tuple(index)] = value

    for _ in range(sum(shape) + 3):
        if cell == last:
            break
        mark(cell, FREE)
        axis = 0
        if t_max[1] < t_max[axis]:
            axis = 1
        if t_max[2] < t_max[axis]:
            axis = 2
        if t_max[axis] > t1:
            break
        cell[axis] += step[axis]
        if cell[axis] < 0 or cell[axis] >= shape[axis]:
            break
        t_max[axis] += t_delta[axis]
    mark(last, OCCUPIED if occupy_end else FREE)


def _reference(states, grid, origins, ends, hit) -> None:
    grid_origin, resolution = grid
    for r in range(len(ends)):
        src = origins[0] if len(origins) == 1 else origins[r]
        o = (src - grid_origin) / resolution
        _reference_walk(states, o, (ends[r] - grid_origin) / resolution - o, bool(hit[r]))


def _random_rays(rng, count, shared_origin):
    """Rays inside, across and outside a 6 x 5 x 4 m box, some along grid lines and axes."""
    ends = rng.uniform([-2, -2, -2], [8, 7, 6], (count, 3))
    ends[: count // 4] = np.round(ends[: count // 4] * 2) / 2  # on cell borders
    origins = rng.uniform([-1, -1, -1], [7, 6, 5], (1 if shared_origin else count, 3))
    if not shared_origin:
        ends[count // 4 : count // 2, 1:] = origins[count // 4 : count // 2, 1:]  # along x
    return origins, ends, rng.random(count) < 0.7


@pytest.mark.parametrize("shared_origin", [True, False])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_walk_marks_the_same_cells_as_the_reference(shared_origin, seed) -> None:
    rng = np.random.default_rng(seed)
    grid_origin, resolution = np.array([0.0, 0.0, 0.0]), 0.25
    expected = np.zeros((24, 20, 16), dtype=np.uint8)
    expected[rng.random(expected.shape) < 0.02] = OCCUPIED  # surfaces seen before
    states = expected.copy()
    origins, ends, hit = _random_rays(rng, 600, shared_origin)
    _reference(expected, (grid_origin, resolution), origins, ends, hit)
    integrate_rays_kernel(states, grid_origin, resolution, origins, ends, hit, np.zeros(0))
    assert (expected == FREE).sum() > 1000 and (expected == OCCUPIED).sum() > 200
    np.testing.assert_array_equal(states, expected)


@pytest.mark.parametrize("seed", [0, 1])
def test_walks_started_part_way_free_a_subset_of_the_full_walks_cells(seed) -> None:
    """Off cell borders; on one, a walk that starts part way may break a tie the other way."""
    rng = np.random.default_rng(seed)
    grid_origin, resolution = np.array([0.0, 0.0, 0.0]), 0.25
    origins, ends, hit = _random_rays(rng, 600, shared_origin=True)
    ends += rng.normal(0.0, 1e-3, ends.shape)
    full = np.zeros((24, 20, 16), dtype=np.uint8)
    integrate_rays_kernel(full, grid_origin, resolution, origins, ends, hit, np.zeros(0))
    from_origin = np.zeros_like(full)
    integrate_rays_kernel(from_origin, grid_origin, resolution, origins, ends, hit, np.zeros(600))
    part = np.zeros_like(full)
    integrate_rays_kernel(part, grid_origin, resolution, origins, ends, hit, rng.random(600))
    np.testing.assert_array_equal(from_origin, full)
    assert np.array_equal(part == OCCUPIED, full == OCCUPIED)
    assert not np.any((part == FREE) & (full != FREE))
    assert (part == FREE).sum() < 0.9 * (full == FREE).sum()


def test_walks_started_at_their_end_only_set_their_end_cells() -> None:
    grid_origin, resolution = np.array([0.0, 0.0, 0.0]), 1.0
    states = np.zeros((10, 4, 4), dtype=np.uint8)
    ends = np.array([[8.5, 1.5, 1.5], [6.5, 2.5, 2.5]])
    origins = np.array([[0.5, 1.5, 1.5]])
    integrate_rays_kernel(
        states, grid_origin, resolution, origins, ends, np.array([True, False]), np.ones(2)
    )
    assert states[8, 1, 1] == OCCUPIED and states[6, 2, 2] == FREE
    assert np.count_nonzero(states) == 2


@pytest.mark.parametrize("threads", [2, 3])
@pytest.mark.parametrize("shared_origin", [True, False])
def test_walks_dealt_out_to_threads_give_the_one_thread_map(threads, shared_origin) -> None:
    rng = np.random.default_rng(threads)
    grid_origin, resolution = np.array([0.0, 0.0, 0.0]), 0.25
    before = np.zeros((24, 20, 16), dtype=np.uint8)
    before[rng.random(before.shape) < 0.02] = OCCUPIED
    # enough rays to be dealt out; many cross cells other rays end on
    origins, ends, hit = _random_rays(rng, 4 * MIN_RAYS_PER_THREAD, shared_origin)
    one, dealt = before.copy(), before.copy()
    integrate_rays_kernel(one, grid_origin, resolution, origins, ends, hit, np.zeros(0))
    integrate_rays_kernel(dealt, grid_origin, resolution, origins, ends, hit, np.zeros(0), threads)
    assert (one == OCCUPIED).sum() > (before == OCCUPIED).sum() + 500
    np.testing.assert_array_equal(dealt, one)
