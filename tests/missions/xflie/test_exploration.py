import math

import numpy as np

from fake_platform import FakePlatform, fake_context, headings_apart
from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN
from seminspect.missions.xflie.config import survey_headings
from seminspect.missions.xflie.exploration import FRONTIER_MIN_DISTANCE, Exploration


def test_a_survey_turns_full_circle_in_equal_steps() -> None:
    ctx, _ = fake_context()
    Exploration(ctx).survey()
    platform = ctx.platform
    count = survey_headings(ctx.params.fov_deg, ctx.config.exploration.survey_overlap)
    assert platform.frames == count
    steps = headings_apart(platform.headings)
    assert len(steps) == count - 1
    assert np.allclose(steps, 2 * math.pi / count)


def test_a_survey_stops_when_the_time_is_spent() -> None:
    platform = FakePlatform()
    ctx, _ = fake_context(platform)
    platform.wait(ctx.config.time_budget_s)
    Exploration(ctx).survey()
    assert platform.frames == 0


def half_known(ctx) -> None:
    """The west half of the map known free, the east half unknown."""
    states = ctx.occupancy.states
    states[:] = UNKNOWN
    states[: states.shape[0] // 2] = FREE


def test_exploration_drives_to_a_frontier_surveys_and_remembers_it() -> None:
    platform = FakePlatform(position=(-6.0, 0.0, 0.7))
    ctx, events = fake_context(platform)
    half_known(ctx)
    exploration = Exploration(ctx)
    assert exploration.explore()
    assert "frontier" in events.kinds()
    goal = np.array(events.events[-1]["goal"])
    assert abs(goal[0]) < 1.5  # on the boundary with the unknown half
    assert np.linalg.norm((platform.position - goal)[:2]) <= 1.5 + 0.05
    assert platform.frames > 0  # it surveyed there
    assert exploration.is_spent(goal)
    assert not exploration.is_spent(goal + np.array([FRONTIER_MIN_DISTANCE + 0.1, 0.0, 0.0]))


def test_no_frontier_means_no_exploration() -> None:
    ctx, events = fake_context()  # everything known
    assert not Exploration(ctx).explore()
    assert events.kinds() == []


def test_exploration_chooses_only_among_the_frontiers_it_may_keep() -> None:
    platform = FakePlatform(position=(-1.0, 0.0, 0.7))
    ctx, events = fake_context(platform)
    states = ctx.occupancy.states
    states[:] = UNKNOWN
    states[10:30] = FREE  # x in [-5, 5) known: a frontier at each end, the west one nearer
    exploration = Exploration(ctx)
    assert not exploration.explore(keep=lambda goal: False)
    assert events.kinds() == [] and platform.frames == 0 and not exploration.spent_frontiers
    assert exploration.explore(keep=lambda goal: goal[0] > 0.0)
    assert events.events[-1]["goal"][0] > 4.0  # the east frontier, though the west is nearer
    assert platform.position[0] > 3.0


def test_an_aerial_robot_flies_to_a_frontier_level_round_a_wall(monkeypatch) -> None:
    # A 3 m wall across the known half, open only at its north end: over it is shorter, but
    # the robot keeps its height and goes round.
    platform = FakePlatform(position=(-6.0, 0.0, 2.0))
    ctx, events = fake_context(platform, settings={"mode": "aerial"}, height=8.0)
    half_known(ctx)
    wall = ctx.occupancy.world_to_index([[-3.0, -10.0, -0.25], [-2.5, 6.0, 3.0]])
    ctx.occupancy.states[tuple(slice(a, b + 1) for a, b in wall.T)] = OCCUPIED
    flown = []
    move_to = platform.move_to
    monkeypatch.setattr(
        platform, "move_to", lambda point, yaw=None: flown.append(tuple(point)) or move_to(point)
    )
    assert Exploration(ctx).explore()
    assert "frontier" in events.kinds()
    heights = np.array(flown)[:, 2]
    assert np.allclose(heights, 2.0) and max(abs(p[1]) for p in flown) > 6.0
