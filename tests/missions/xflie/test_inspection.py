import numpy as np
import pytest
from scipy import ndimage

from fake_platform import FakePlatform, fake_context
from seminspect.graphs.lsg.model import TargetStatus
from seminspect.mapping.voxel import OCCUPIED
from seminspect.missions.xflie.inspection import (
    ROOF_CLEARANCE_M,
    LevelInspection,
    dilate,
    platform_vfov,
)
from seminspect.perception.observation import Observation
from seminspect.planning.view_planner import ViewConstraints


def inspection_of_a_car(platform=None, settings=None, height=3.0):
    ctx, events = fake_context(platform or FakePlatform(), settings=settings, height=height)
    ctx.graph.register_target(Observation([3.5, 0.0, 0.7], label="car", score=0.9, mask_area=1))
    ctx.graph.optimise_targets()
    view = ViewConstraints(
        d_view=ctx.config.inspection.d_view,
        overlap_h=0.6,
        overlap_v=0.6,
        hfov_deg=ctx.params.fov_deg,
        vfov_deg=platform_vfov(ctx.params),
    )
    inspection = LevelInspection(ctx, view, camera_pitch=0.0)
    return ctx, events, inspection, ctx.graph.target("car-0")


def aerial_inspection_begun(platform):
    """An aerial robot's inspection of the car, begun where the robot is."""
    ctx, events, inspection, car = inspection_of_a_car(
        platform, settings={"mode": "aerial"}, height=8.0
    )
    with ctx.timers("graph"):
        ctx.graph.begin_inspection(car.id, ctx.view_pose(image=None))
    return ctx, events, inspection, car


def test_a_ground_robot_circles_the_target_once_and_leaves_it_inspected() -> None:
    ctx, events, inspection, car = inspection_of_a_car(FakePlatform(position=(1.0, 0.0, 0.7)))
    assert inspection.inspect(car)
    assert car.status is TargetStatus.INSPECTED and len(car.levels) == 1
    assert len(car.levels[0].poses) >= 3
    assert inspection.closed_levels == [True]  # ended by the cap: blank images never match
    assert events.kinds().count("level-complete") == 1
    assert ctx.recorder.record().level_endings.cap == 1
    assert not ctx.unreachable


def test_an_inspection_with_too_few_views_is_cancelled() -> None:
    platform = FakePlatform(position=(1.0, 0.0, 0.7))
    ctx, events, inspection, car = inspection_of_a_car(platform)
    platform.wait(ctx.config.time_budget_s - 1.0)  # time for one view only
    assert not inspection.inspect(car)
    assert ctx.unreachable == {"car-0"}
    assert "inspection-cancelled" in events.kinds()
    assert car.status is not TargetStatus.INSPECTED and ctx.graph.inspecting is None


def test_an_aerial_robot_climbs_only_while_the_target_rises_above_its_view() -> None:
    platform = FakePlatform(position=(1.0, 0.0, 2.0))
    _ctx, events, inspection, car = aerial_inspection_begun(platform)
    assert not inspection.climb(car, heights=[1.4])  # the robot already sees it from above
    assert platform.position[2] == 2.0
    assert inspection.climb(car, heights=[12.0])
    assert platform.position[2] == 2.0 + inspection.view.vertical_step
    assert events.kinds()[-1] == "level" and len(car.levels) == 2


def test_an_aerial_robot_climbs_once_more_to_see_a_roof_its_view_already_reaches() -> None:
    platform = FakePlatform(position=(1.0, 0.0, 2.0))
    _ctx, events, inspection, car = aerial_inspection_begun(platform)
    roof = 2.0 + ROOF_CLEARANCE_M / 2  # within the view, but not below the robot by the margin
    assert inspection.climb(car, heights=[roof])
    assert platform.position[2] == 2.0 + inspection.view.vertical_step
    assert events.kinds()[-1] == "level" and len(car.levels) == 2
    assert not inspection.climb(car, heights=[roof])  # now above it


def test_an_aerial_robot_does_not_climb_into_structure_it_has_mapped_above_it() -> None:
    platform = FakePlatform(position=(1.0, 0.0, 2.0))
    ctx, events, inspection, car = aerial_inspection_begun(platform)
    ctx.occupancy.states[:, :, ctx.occupancy.world_to_index([0, 0, 3.5])[2]] = OCCUPIED  # a slab
    assert not inspection.climb(car, heights=[12.0])
    assert platform.position[2] == 2.0 and platform.distance_travelled == 0.0
    assert events.kinds()[-1] == "climb-blocked" and len(car.levels) == 1


def test_a_mask_grows_by_four_connected_steps() -> None:
    mask = np.zeros((9, 9), bool)
    mask[4, 4] = True
    grown = dilate(mask, 2)
    assert grown.sum() == 13  # a diamond of radius 2
    assert grown[4, 6] and grown[2, 4] and not grown[6, 6]


@pytest.mark.parametrize("seed", range(10))
def test_dilation_equals_scipys_binary_dilation(seed: int) -> None:
    rng = np.random.default_rng(seed)
    mask = rng.random((48, 64)) < rng.uniform(0.001, 0.2)
    mask[:, 0] |= rng.random(48) < 0.3  # pixels on the image's edges
    mask[-1] |= rng.random(64) < 0.3
    for pixels in (0, 1, 2, 5):
        expected = ndimage.binary_dilation(mask, iterations=pixels) if pixels else mask
        np.testing.assert_array_equal(dilate(mask, pixels), expected)
