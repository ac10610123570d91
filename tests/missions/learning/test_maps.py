"""The robots' maps: marked returns, carved free space, the ego cells around the robot and
eq (3)'s visit scores."""

import numpy as np

from seminspect.missions.learning.maps import (
    BINARY_VALUES,
    FREE,
    OCCUPIED,
    THREE_STATE_VALUES,
    UNSEEN,
    carve_free,
    ego_offsets,
    gather_ego,
    mark_hits,
    spatial_visit_scores,
    update_maps,
)


def test_spatial_visit_scores_are_eq_3_on_a_known_histogram():
    scores, totals = spatial_visit_scores(np.array([[1, 1, 2, 0], [0, 0, 0, 0]]))
    p = np.array([0.25, 0.25, 0.5])
    np.testing.assert_allclose(scores[0, :3], -p * np.log(p), rtol=1e-6)
    assert scores[0, 3] == 0.0 and not scores[1].any()
    np.testing.assert_array_equal(totals, [4.0, 0.0])


def test_a_return_marks_its_cell_in_its_own_robots_map():
    occupancy = np.zeros((2, 4, 4, 4), dtype=np.uint8)  # (robot, z, y, x) at 1 m cells
    starts = np.array([[10.5, 0.5, 0.5], [0.5, 0.5, 0.5]], dtype=np.float32)
    dirs = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], dtype=np.float32)
    shift = np.array([[10.0, 0.0, 0.0]])  # room 0 sits 10 m along x in the shared scene
    distance = np.array([2.0, np.inf])  # the second ray missed
    mark_hits(occupancy, np.array([1, 0]), starts, dirs, distance, shift, np.array([0, 0]), 1.0)
    assert occupancy[1, 0, 0, 2] == 1 and occupancy.sum() == 1


def test_ego_cells_are_centred_on_the_robot_and_outside_reads_occupied():
    offsets = ego_offsets(3, 1.0)
    assert offsets.shape == (27, 3) and np.array_equal(offsets[13], [0.0, 0.0, 0.0])
    assert np.array_equal(offsets[14], [1.0, 0.0, 0.0])  # x varies fastest
    occupancy = np.zeros((1, 3, 3, 3), dtype=np.uint8)
    visits = np.full((1, 3, 3, 3), 7, dtype=np.uint16)
    out_occupancy = np.empty((1, 27), dtype=np.float32)
    out_visits = np.empty((1, 27), dtype=np.float32)
    position, yaw = np.array([[0.5, 1.5, 1.5]]), np.array([0.0])
    args = occupancy, visits, np.array([0]), position, yaw, offsets, 1.0
    gather_ego(*args, BINARY_VALUES, out_occupancy, out_visits)
    behind = offsets[:, 0] < 0  # x = -0.5 m lies outside the map
    assert np.all(out_occupancy[0, behind] == 1.0) and np.all(out_visits[0, behind] == 0.0)
    assert np.all(out_occupancy[0, ~behind] == 0.0) and np.all(out_visits[0, ~behind] == 7.0)
    # three-state: unknown and outside read 0.5, free 0, occupied 1
    occupancy[0, 1, 1, 0], occupancy[0, 1, 1, 1] = FREE, OCCUPIED
    gather_ego(*args, THREE_STATE_VALUES, out_occupancy, out_visits)
    ego = out_occupancy[0].reshape(3, 3, 3)  # the robot in map cell x 0: ego x = map x + 1
    assert ego[1, 1, 1] == 0.0 and ego[1, 1, 2] == 1.0
    assert np.all(out_occupancy[0, behind] == 0.5)
    assert np.count_nonzero(out_occupancy[0] == 0.5) == 25


def _carve(occupancy, starts, dirs, distance, reach=100.0):
    n = len(distance)
    args = (
        occupancy,
        np.zeros(n, dtype=np.int64),
        np.asarray(starts, dtype=np.float32),
        np.asarray(dirs, dtype=np.float32),
        np.asarray(distance, dtype=np.float64),
        np.zeros((1, 3)),
        np.zeros(n, dtype=np.int64),
        1.0,
    )
    carve_free(*args, reach)
    mark_hits(*args)


def test_a_ray_clears_a_stale_occupied_cell_and_marks_its_return():
    occupancy = np.full((1, 1, 1, 8), UNSEEN, dtype=np.uint8)  # one row of 1 m cells along x
    occupancy[0, 0, 0, 2] = OCCUPIED  # a noise hit of an earlier step
    _carve(occupancy, [[0.5, 0.5, 0.5]], [[1.0, 0.0, 0.0]], [4.3])
    np.testing.assert_array_equal(occupancy[0, 0, 0], [FREE] * 4 + [OCCUPIED] + [UNSEEN] * 3)


def test_within_one_step_a_hit_wins_over_a_pass():
    occupancy = np.zeros((1, 1, 1, 8), dtype=np.uint8)
    # ray 0 passes through cell 3 that ray 1 hits (ray 1 is cast after it)
    _carve(occupancy, [[0.5, 0.5, 0.5]] * 2, [[1.0, 0.0, 0.0]] * 2, [6.0, 3.0])
    expected = [FREE] * 3 + [OCCUPIED, FREE, FREE, OCCUPIED, UNSEEN]
    np.testing.assert_array_equal(occupancy[0, 0, 0], expected)


def test_a_miss_carves_up_to_reach_and_the_walk_stops_at_the_grid_edge():
    occupancy = np.zeros((1, 1, 1, 8), dtype=np.uint8)
    _carve(occupancy, [[0.5, 0.5, 0.5]], [[1.0, 0.0, 0.0]], [np.inf], reach=2.2)
    np.testing.assert_array_equal(occupancy[0, 0, 0], [FREE] * 3 + [UNSEEN] * 5)
    _carve(occupancy, [[0.5, 0.5, 0.5]], [[-1.0, 0.0, 0.0]], [np.inf])  # leaves the grid
    assert occupancy[0, 0, 0, 0] == FREE


def test_the_ray_walk_visits_the_cells_a_dense_sampling_does():
    rng = np.random.default_rng(4)
    for _ in range(20):
        start = rng.uniform(1.0, 7.0, 3)
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        length = rng.uniform(0.5, 6.0)
        occupancy = np.zeros((1, 8, 8, 8), dtype=np.uint8)
        start32, dir32 = start.astype(np.float32), direction.astype(np.float32)
        carve_free(
            occupancy,
            np.zeros(1, dtype=np.int64),
            start32[None],
            dir32[None],
            np.array([length]),
            np.zeros((1, 3)),
            np.zeros(1, dtype=np.int64),
            1.0,
            100.0,
        )
        t = np.linspace(0.0, length, 20_000, endpoint=False)
        points = start32.astype(np.float64) + t[:, None] * dir32.astype(np.float64)
        inside = np.all((points >= 0) & (points < 8), axis=1)
        cells = {tuple(c) for c in np.floor(points[inside]).astype(int)[:, ::-1]}
        carved = set(zip(*np.nonzero(occupancy[0] == FREE), strict=True))
        assert carved == cells, (start, direction, length)


def _two_rays_per_room(rooms: int):
    """Per room: ray 0 along +x to a return at 3.2 m, ray 1 along +y to one at 2.2 m; 1 m cells,
    every robot at (0.5, 0.5, 0.5) of its own room (room ``r`` shifted by 10 r along x)."""
    row = np.repeat(np.arange(rooms), 2)
    shift = np.outer(np.arange(rooms) * 10.0, (1.0, 0.0, 0.0))
    starts = (shift[row] + 0.5).astype(np.float32)
    dirs = np.tile(np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], np.float32), (rooms, 1))
    distance = np.tile([3.2, 2.2], rooms)
    return row, starts, dirs, distance, shift


def test_only_the_flagged_rays_carve_and_every_return_is_marked():
    row, starts, dirs, distance, shift = _two_rays_per_room(1)
    occupancy = np.zeros((1, 1, 6, 6), dtype=np.uint8)
    update_maps(
        occupancy, row, starts, dirs, distance, shift, row, 1.0, np.array([True, False]), 9.0
    )
    np.testing.assert_array_equal(occupancy[0, 0, 0], [FREE] * 3 + [OCCUPIED, UNSEEN, UNSEEN])
    np.testing.assert_array_equal(
        occupancy[0, 0, 1:, 0], [UNSEEN, OCCUPIED, UNSEEN, UNSEEN, UNSEEN]
    )
    binary = np.zeros_like(occupancy)  # no carve flags: the binary map only marks returns
    update_maps(binary, row, starts, dirs, distance, shift, row, 1.0, None, 9.0)
    assert np.count_nonzero(binary) == 2 and np.all(binary[occupancy == OCCUPIED] == OCCUPIED)


def test_rooms_dealt_to_two_threads_give_the_same_maps():
    row, starts, dirs, distance, shift = _two_rays_per_room(5)  # 5 rooms: blocks split them
    maps = []
    for threads in (1, 2):
        occupancy = np.zeros((5, 1, 6, 6), dtype=np.uint8)
        carve = np.tile([True, False], 5)
        update_maps(occupancy, row, starts, dirs, distance, shift, row, 1.0, carve, 9.0, threads)
        maps.append(occupancy)
    np.testing.assert_array_equal(maps[0], maps[1])
    assert np.all(maps[0] == maps[0][:1])  # every room its own map, all alike
