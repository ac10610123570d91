import math

import numpy as np
import pytest

from fake_platform import fake_context
from seminspect.core.errors import PlanningError
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.missions.xflie.approach import local_planner
from seminspect.missions.xflie.links import TargetLinks, first_route
from seminspect.perception.observation import Observation


class _Planner:
    def __init__(self, answer) -> None:
        self.answer = answer
        self.calls = 0

    def plan(self, occupancy, start, goal):
        self.calls += 1
        if self.answer is None:
            raise PlanningError("no route")
        return self.answer


def test_the_first_planner_that_finds_a_route_wins() -> None:
    failing, found, unused = _Planner(None), _Planner("route"), _Planner("other")
    assert first_route([failing, found, unused], None, np.zeros(3), np.ones(3)) == "route"
    assert (failing.calls, found.calls, unused.calls) == (1, 1, 0)
    assert first_route([_Planner(None)], None, np.zeros(3), np.ones(3)) is None


def test_link_routes_keep_half_a_cell_diagonal_more_clearance_first() -> None:
    ctx, _ = fake_context()
    local = local_planner(ctx.config)
    strict, plain = TargetLinks(ctx, local).link_planners()
    slack = 0.5 * ctx.occupancy.resolution * math.sqrt(2)  # a ground robot plans in 2D
    assert strict.model.robot_radius == pytest.approx(local.model.robot_radius + slack)
    assert plain.model.robot_radius == pytest.approx(local.model.robot_radius)
    assert strict.model.unknown_cost is None  # known free space only


def inspect_by_hand(graph, name: str, x: float) -> None:
    """Register a car at ``x`` and inspect it with four views around it."""
    graph.register_target(Observation([x, 0.0, 0.7], label="car", score=0.9, mask_area=100))
    graph.optimise_targets()
    graph.begin_inspection(name, Observation.view_pose([x - 2.5, 0.0, 0.7]))
    for dx, dy in ((0.0, -2.5), (2.5, 0.0), (0.0, 2.5), (-2.5, 0.0)):
        graph.register_pose(Observation.view_pose([x + dx, dy, 0.7], quat_from_yaw(0.0)))
    graph.close_level(close_ring=False)
    graph.finish_inspection()


def test_a_newly_inspected_target_is_linked_to_its_inspected_neighbour() -> None:
    ctx, _ = fake_context(size=30.0)
    inspect_by_hand(ctx.graph, "car-0", -6.0)
    inspect_by_hand(ctx.graph, "car-1", 6.0)
    car = ctx.graph.target("car-1")
    assert ctx.graph.edge("car-0", "car-1") is None
    TargetLinks(ctx, local_planner(ctx.config)).connect(car)
    assert ctx.graph.edge("car-0", "car-1") is not None
