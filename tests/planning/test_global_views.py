import math

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.mapping.voxel import VoxelMap
from seminspect.planning.global_views import (
    InspectionRegion,
    global_view_plan,
    grid_points,
    pose_is_clear,
)
from seminspect.planning.view_planner import ViewConstraints

VIEW = ViewConstraints(d_view=2.0, overlap_h=0.6, overlap_v=0.6, hfov_deg=69.5, vfov_deg=45.0)
#: A 3.3 m wide, 2 m high rectangle on the plane x = 10.
RECT = np.array([[10.0, 1.0, 0.5], [10.0, 4.3, 0.5], [10.0, 4.3, 2.5], [10.0, 1.0, 2.5]])


def wall_map(extra_boxes=()):
    boxes = [[[10.0, 0.0, 0.0], [11.0, 6.0, 4.0]], *extra_boxes]
    return VoxelMap.from_boxes([0, 0, 0], [12, 6, 4], 0.1, boxes)


def test_spacing_follows_the_footprint_and_overlap():
    du = 2 * math.tan(math.radians(69.5 / 2)) * 2.0 * 0.4
    dv = 2 * math.tan(math.radians(45.0 / 2)) * 2.0 * 0.4
    points = grid_points(InspectionRegion("r", RECT), VIEW)
    # floor(3.3 / du) + 1 = 3 columns, floor(2 / dv) + 1 = 4 rows, centred on the rectangle
    assert len(points) == 12
    np.testing.assert_allclose(
        np.unique(points[:, 1].round(6)), 2.65 + du * np.array([-1, 0, 1]), atol=1e-6
    )
    np.testing.assert_allclose(
        np.unique(points[:, 2].round(6)), 1.5 + dv * np.array([-1.5, -0.5, 0.5, 1.5]), atol=1e-6
    )
    np.testing.assert_allclose(points[:, 0], 10.0)


def test_only_intersections_inside_the_polygon_are_kept():
    triangle = np.array([[10.0, 0.0, 0.0], [10.0, 4.0, 0.0], [10.0, 0.0, 4.0]])
    points = grid_points(InspectionRegion("t", triangle), VIEW)
    assert len(points) > 0
    assert np.all(points[:, 1] + points[:, 2] < 4.0)


def test_views_face_the_surface_from_d_view_on_the_free_side():
    plan = global_view_plan(
        InspectionRegion("r", RECT),
        wall_map(),
        VIEW,
        robot_radius=0.3,
        height_limits=(0.3, 3.7),
        viewer=(1, 3, 1),
    )
    assert len(plan.positions) == 12 and plan.dropped == 0 and plan.repaired == 0
    np.testing.assert_allclose(plan.positions[:, 0], 8.0)
    np.testing.assert_allclose(plan.yaws, 0.0)
    np.testing.assert_allclose(plan.normal, [-1.0, 0.0, 0.0])


def test_a_pose_inside_an_obstacle_is_repaired_or_dropped():
    pillar = [[7.6, 2.3, 0.0], [8.4, 3.0, 4.0]]
    plan = global_view_plan(
        InspectionRegion("r", RECT),
        wall_map([pillar]),
        VIEW,
        robot_radius=0.3,
        height_limits=(0.3, 3.7),
        viewer=(1, 3, 1),
    )
    assert plan.repaired + plan.dropped == 4
    prior = wall_map([pillar])
    assert all(pose_is_clear(prior, p, 0.3) for p in plan.positions)


@pytest.mark.parametrize(
    ("vertices", "message"),
    [
        ([[0, 0, 0], [0, 1, 0]], ">= 3 vertices"),
        ([[0, 0, 0], [0, 1, 0], [0, 2, 0]], "no area"),
        ([[0, 0, 0], [0, 1, 0], [0, 1, 1], [0.3, 0, 1]], "not planar"),
        ([[0, 0, 0], [1, 0, 0], [1, 1, 0]], "wall-like"),
        ([[0, 0, 0], [0, 1, np.nan], [0, 1, 1]], "NaN"),
    ],
)
def test_bad_regions_are_refused_with_a_reason(vertices, message):
    with pytest.raises(InvalidInputError, match=message):
        InspectionRegion("bad", np.array(vertices, dtype=float))


def test_contains_uses_outline_and_slab():
    region = InspectionRegion("r", RECT)
    inside = region.contains([[10.2, 2.0, 1.0], [10.2, 0.5, 1.0], [11.0, 2.0, 1.0]], slab=0.5)
    assert inside.tolist() == [True, False, False]


def test_without_free_space_the_views_face_the_viewer():
    surface_only = VoxelMap.from_boxes([0, 0, 0], [12, 6, 4], 0.1, [[[10, 0, 0], [10.1, 6, 4]]])
    surface_only.states[surface_only.states == 1] = 0  # a point cloud: occupied or unknown
    region = InspectionRegion("r", RECT)
    for viewer, x in (((1, 3, 1), 8.0), ((11.5, 3, 1), 12.0)):
        plan = global_view_plan(
            region, surface_only, VIEW, robot_radius=0.3, height_limits=(0.3, 3.7), viewer=viewer
        )
        np.testing.assert_allclose(plan.positions[:, 0], x)
