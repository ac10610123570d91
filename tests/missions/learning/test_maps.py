"""The robots' maps: marked returns, the ego cells around the robot and eq (3)'s visit scores."""

import numpy as np

from seminspect.missions.learning.maps import (
    ego_offsets,
    gather_ego,
    mark_hits,
    spatial_visit_scores,
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
    gather_ego(
        occupancy, visits, np.array([0]), position, yaw, offsets, 1.0, out_occupancy, out_visits
    )
    behind = offsets[:, 0] < 0  # x = -0.5 m lies outside the map
    assert np.all(out_occupancy[0, behind] == 1.0) and np.all(out_visits[0, behind] == 0.0)
    assert np.all(out_occupancy[0, ~behind] == 0.0) and np.all(out_visits[0, ~behind] == 7.0)
