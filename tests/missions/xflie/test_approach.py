import math

import numpy as np

from fake_platform import fake_context, headings_apart
from seminspect.missions.xflie.approach import (
    ARRIVAL_FALLBACKS,
    PLANNING_MARGIN,
    Approach,
    baseline_planner,
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
