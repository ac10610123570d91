import math

import numpy as np

from fake_platform import FakePlatform, fake_context, headings_apart
from seminspect.mapping.voxel import OCCUPIED
from seminspect.missions.xflie.approach import (
    ARRIVAL_FALLBACKS,
    PLANNING_MARGIN,
    Approach,
    baseline_planner,
    level_flight_planner,
    local_planner,
    planning_clearance,
)
from seminspect.perception.observation import Observation
from seminspect.planning.hierarchical import HierarchicalPlanner
from seminspect.planning.volumetric import RebuildingVolumetricPlanner


def context_with_a_car(at=(6.0, 0.0, 0.7)):
    ctx, events = fake_context()
    ctx.graph.register_target(Observation(list(at), label="car", score=0.9, mask_area=5000))
    ctx.graph.optimise_targets()
    return ctx, events, ctx.graph.target("car-0")


def approach(ctx) -> Approach:
    return Approach(ctx, HierarchicalPlanner(ctx.graph))


def test_the_robot_reaches_a_target_within_epsilon() -> None:
    ctx, events, car = context_with_a_car()
    assert approach(ctx).reach(car)
    distance = np.linalg.norm((ctx.platform.position - car.position)[:2])
    assert distance <= ctx.params.epsilon + 0.05
    assert events.kinds()[0] == "selected" and events.kinds()[-1] == "arrived"
    assert not ctx.recorder.plans  # nothing inspected yet: no leg over the graph


def test_wider_arrival_radii_are_tried_in_turn(monkeypatch) -> None:
    ctx, events, car = context_with_a_car()
    tried = []

    def go_to(goal, radius, planner=None, **kwargs) -> bool:
        tried.append(radius)
        return False

    monkeypatch.setattr(ctx.navigator, "go_to", go_to)
    assert not approach(ctx).reach(car)
    assert tried == [ctx.params.epsilon + extra for extra in ARRIVAL_FALLBACKS]
    assert "arrived" not in events.kinds()


def test_a_target_not_seen_on_arrival_is_not_confirmed_after_three_looks() -> None:
    ctx, _, car = context_with_a_car()
    assert not approach(ctx).confirm(car)
    assert ctx.platform.frames == 3
    turns = headings_apart(ctx.platform.headings)
    assert np.allclose(turns, [math.radians(35), math.radians(70)])


def test_the_planners_follow_the_configuration() -> None:
    ctx, _ = fake_context(settings={"planner": "volumetric"})
    local = local_planner(ctx.config)
    assert local.model.robot_radius > ctx.config.robot.radius  # a margin beyond the body
    assert isinstance(baseline_planner(ctx.config), RebuildingVolumetricPlanner)
    hierarchical, _ = fake_context()
    assert baseline_planner(hierarchical.config) is None


def test_aerial_robots_keep_a_wider_berth_than_ground_robots() -> None:
    ground, _ = fake_context()
    aerial, _ = fake_context(settings={"mode": "aerial"})
    assert planning_clearance(ground.config) == ground.config.robot.radius + PLANNING_MARGIN
    assert planning_clearance(aerial.config) > planning_clearance(ground.config)
    assert local_planner(aerial.config).model.robot_radius == planning_clearance(aerial.config)


def aerial_context_over_a_block(roof: float):
    """An aerial robot at 2 m, 7 m west of a 10 x 10 m block with its roof at ``roof``."""
    platform = FakePlatform(position=(-6.0, 0.0, 2.0))
    settings = {"mode": "aerial", "preset": "collapsed-buildings"}
    ctx, events = fake_context(platform, settings=settings, size=30.0, height=12.0)
    block = ctx.occupancy.world_to_index([[1.0, -5.0, -0.25], [11.0, 5.0, roof]])
    ctx.occupancy.states[tuple(slice(a, b + 1) for a, b in block.T)] = OCCUPIED
    ctx.graph.register_target(Observation([6.0, 0.0, 3.0], label="building", score=0.9))
    ctx.graph.optimise_targets()
    return ctx, events, ctx.graph.target("building-0")


def test_an_aerial_robot_reaches_a_target_level_at_its_own_height() -> None:
    # Within ε (5 m) of the target only the space over the 4 m roof lies: the robot must not
    # climb there, but come round beside the block at its height, within a wider radius.
    ctx, _, building = aerial_context_over_a_block(roof=4.0)
    assert approach(ctx).reach(building)
    assert ctx.platform.position[2] == 2.0
    horizontal = np.linalg.norm((ctx.platform.position - building.position)[:2])
    assert ctx.params.epsilon < horizontal <= ctx.params.epsilon + ARRIVAL_FALLBACKS[-1] + 0.05


def test_the_level_flight_planner_keeps_the_height_it_is_given() -> None:
    ctx, _, _ = aerial_context_over_a_block(roof=1.0)  # a block low enough to fly over
    level = level_flight_planner(ctx.navigator.planner, 2.0)
    clearance = ctx.navigator.planner.model.robot_radius
    assert level.mode == "ground" and level.band == (2.0 - clearance, 2.0 + clearance)
    path = level.plan(ctx.occupancy, ctx.platform.position, (13.5, 0.0, 2.0), goal_radius=0.5)
    assert np.allclose(path.waypoints[:, 2], 2.0)
    assert np.abs(path.waypoints[:, 1]).max() > 5.0  # round the block, not over it


def inspected_in_two_levels(ctx):
    """A target inspected at 2 m and, after a climb at the end of Level-0, at 3.5 m."""
    graph = ctx.graph
    graph.register_target(Observation([6.0, 0.0, 1.0], label="building", score=0.9))
    graph.optimise_targets()
    building = graph.target("building-0")
    ring = [(0.0, 0.0), (0.0, 4.0), (-2.0, 6.0)]
    graph.begin_inspection(building.id, Observation.view_pose([*ring[0], 2.0]))
    for xy in ring[1:]:
        graph.register_pose(Observation.view_pose([*xy, 2.0]))
    graph.close_level(close_ring=False)
    climb_start = [*ring[-1], 2.0]
    graph.begin_level(Observation.view_pose([*ring[-1], 3.5]), via=[climb_start])
    for xy in ring[-2::-1]:
        graph.register_pose(Observation.view_pose([*xy, 3.5]))
    graph.close_level(close_ring=False)
    graph.finish_inspection(every_level=True)
    return building


def test_an_aerial_robot_flies_back_down_the_way_it_climbed(monkeypatch) -> None:
    platform = FakePlatform(position=(0.0, 0.0, 3.5))  # at the upper level's last view
    ctx, events = fake_context(platform, settings={"mode": "aerial"}, height=6.0)
    building = inspected_in_two_levels(ctx)
    flown = []
    move_to = platform.move_to
    monkeypatch.setattr(
        platform, "move_to", lambda point, yaw=None: flown.append(tuple(point)) or move_to(point)
    )
    approach(ctx).descend(building)
    assert np.allclose(platform.position, [0.0, 0.0, 2.0])  # Level-0's start
    climb = [i for i, p in enumerate(flown) if np.allclose(p, (-2.0, 6.0, 2.0))]
    assert climb and all(p[2] == 3.5 for p in flown[: climb[0]])  # down only where it climbed
    assert events.events[-1] == events.events[-1] | {"event": "descended", "reached": True}
    assert ctx.recorder.plans  # a query over the graph


def test_a_robot_at_its_targets_entry_height_does_not_descend() -> None:
    ctx, events = fake_context(FakePlatform(position=(0.0, 4.0, 2.0)), settings={"mode": "aerial"})
    building = inspected_in_two_levels(ctx)
    approach(ctx).descend(building)
    assert np.allclose(ctx.platform.position, [0.0, 4.0, 2.0]) and "descended" not in events.kinds()


def test_an_aerial_robot_takes_a_graph_leg_only_to_a_node_at_its_height() -> None:
    ctx, _ = fake_context(FakePlatform(position=(0.0, 0.0, 2.0)), settings={"mode": "aerial"})
    inspected_in_two_levels(ctx)
    approach(ctx).graph_leg(np.array([-2.0, 9.5, 3.5]))  # nearest node: Level-1's start
    assert np.allclose(ctx.platform.position, [0.0, 0.0, 2.0]) and not ctx.recorder.plans
    approach(ctx).graph_leg(np.array([-2.0, 9.5, 2.0]))  # nearest node: a Level-0 pose
    assert np.allclose(ctx.platform.position, [-2.0, 6.0, 2.0]) and ctx.recorder.plans
