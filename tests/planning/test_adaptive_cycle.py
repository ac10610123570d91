import math

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.planning.adaptive_cycle import deviation_score, plan_cycle, predict_local_path
from seminspect.planning.view_planner import ViewConstraints

VIEW = ViewConstraints(d_view=2.0, overlap_h=0.6, overlap_v=0.6, hfov_deg=69.5, vfov_deg=45.0)


def wall(x):
    """A wall facing -x at ``x``: points every 0.1 m over y 0-10, z 0-3."""
    y, z = np.meshgrid(np.arange(0, 10, 0.1), np.arange(0, 3, 0.1), indexing="ij")
    return np.column_stack([np.full(y.size, x), y.ravel(), z.ravel()])


SEGMENT = np.array([[3.0, 3.0, 1.5], [3.0, 4.1, 1.5], [3.0, 5.2, 1.5]])
YAWS = np.zeros(3)


def test_gamma_s_is_zero_for_equal_paths_and_half_at_one_metre():
    assert deviation_score(0.0) == 0.0
    assert deviation_score(1.0) == pytest.approx(0.5)
    assert deviation_score(3.0) == pytest.approx(0.75)
    with pytest.raises(InvalidInputError):
        deviation_score(-1.0)


def test_prediction_on_the_mapped_wall_follows_the_global_plan():
    path = predict_local_path([3.0, 2.0, 1.5], wall(5.0), SEGMENT, YAWS, VIEW)
    np.testing.assert_allclose(path.positions, SEGMENT, atol=0.06)
    np.testing.assert_allclose(path.yaws, 0.0, atol=0.06)
    assert path.guided.all()


def test_prediction_keeps_d_view_from_a_receded_wall():
    path = predict_local_path([3.0, 2.0, 1.5], wall(6.5), SEGMENT, YAWS, VIEW)
    np.testing.assert_allclose(path.positions[:, 0], 4.5, atol=0.06)
    np.testing.assert_allclose(path.positions[:, 1:], SEGMENT[:, 1:], atol=0.06)


def test_prediction_keeps_the_global_pose_without_surface():
    path = predict_local_path([3.0, 2.0, 1.5], np.empty((0, 3)), SEGMENT, YAWS, VIEW)
    np.testing.assert_array_equal(path.positions, SEGMENT)
    assert not path.guided.any()


def test_cycle_adapts_only_past_the_threshold_and_kabsch_removes_a_shift():
    nominal = plan_cycle([3.0, 2.0, 1.5], wall(5.3), SEGMENT, YAWS, VIEW)
    assert nominal.gamma_s < 0.5 and not nominal.adapt
    moved = plan_cycle([3.0, 2.0, 1.5], wall(6.5), SEGMENT, YAWS, VIEW)
    assert moved.frechet == pytest.approx(1.5, abs=0.06)
    assert moved.gamma_s > 0.5 and moved.adapt
    assert moved.rmse_before == pytest.approx(1.5, abs=0.06)
    assert moved.rmse_after < 0.05
    np.testing.assert_allclose(moved.aligned_global, moved.local_path.positions, atol=0.06)
    baseline = plan_cycle([3.0, 2.0, 1.5], wall(6.5), SEGMENT, YAWS, VIEW, adaptive=False)
    assert baseline.gamma_s == pytest.approx(moved.gamma_s) and not baseline.adapt


def test_yaw_faces_an_oblique_wall():
    angle = math.radians(20)
    points = wall(0.0) @ np.array(
        [[math.cos(angle), -math.sin(angle), 0], [math.sin(angle), math.cos(angle), 0], [0, 0, 1]]
    ).T + [6.0, 0, 0]
    path = predict_local_path([3.0, 2.5, 1.5], points, SEGMENT, YAWS, VIEW)
    assert path.yaws[-1] == pytest.approx(angle, abs=0.1)
