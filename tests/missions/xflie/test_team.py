from dataclasses import dataclass, field

import numpy as np
import pytest

from fake_platform import FakePlatform, car_in_view, fake_context
from seminspect.core.errors import InvalidInputError
from seminspect.mapping.voxel import FREE, UNKNOWN
from seminspect.missions.xflie import XFlie
from seminspect.missions.xflie.sightings import register_targets
from seminspect.missions.xflie.team import Activity, Team, interleave
from seminspect.planning.frontier import find_frontiers


@dataclass
class ScriptedMember:
    """Takes steps of the given durations, then is done."""

    name: str
    durations: list[float]
    clock: float = 0.0
    taken: list[float] = field(default_factory=list)

    @property
    def done(self) -> bool:
        return len(self.taken) == len(self.durations)

    def step(self) -> Activity:
        start = self.clock
        self.clock += self.durations[len(self.taken)]
        self.taken.append(start)
        return Activity(self.name, "work", start, self.clock)


def test_the_member_whose_clock_is_behind_steps_next_and_ties_go_to_the_first() -> None:
    first = ScriptedMember("a", [5.0, 5.0, 1.0])
    second = ScriptedMember("b", [2.0, 2.0, 20.0])
    steps: list[Activity] = []
    interleave([first, second], steps.append)
    # Clocks a: 0, 5, 10, 11 and b: 0, 2, 4, 24; at 0 (a tie) a goes first, at 4 b is behind.
    assert [(s.robot, s.start) for s in steps] == [
        ("a", 0.0), ("b", 0.0), ("b", 2.0), ("b", 4.0), ("a", 5.0), ("a", 10.0),
    ]  # fmt: skip
    assert first.done and second.done


def test_a_step_never_starts_before_a_step_already_taken_by_the_other_robot_began() -> None:
    rng = np.random.default_rng(3)
    members = [ScriptedMember(n, list(rng.uniform(0.5, 30.0, 12))) for n in "ab"]
    steps: list[Activity] = []
    interleave(members, steps.append)
    assert len(steps) == 24
    starts = [s.start for s in steps]
    assert starts == sorted(starts)  # the clock that is behind always moves first


def two_robots(explorer_at, inspector_at) -> tuple[XFlie, XFlie]:
    """Two robots on one graph, each with its own (free, known) map."""
    ctx, _ = fake_context()
    explorer = XFlie(
        ctx.config, FakePlatform(explorer_at), ctx.occupancy, ground_z=0.0, name="explorer"
    )
    inspector = XFlie(
        ctx.config,
        FakePlatform(inspector_at),
        fake_context()[0].occupancy,
        ground_z=0.0,
        graph=explorer.graph,
        name="inspector",
    )
    return explorer, inspector


def test_both_robots_seeing_one_car_leave_one_target_in_the_shared_graph() -> None:
    explorer, inspector = two_robots((0.0, 0.0, 0.7), (0.0, 0.6, 0.7))
    for mission in (explorer, inspector):
        car_in_view(mission.platform)  # type: ignore[arg-type]
        register_targets(mission.ctx, mission.ctx.capture())
    (car,) = explorer.graph.targets()
    assert car.observations == 2
    assert inspector.graph is explorer.graph


def test_a_car_only_one_robot_sees_far_from_the_other_is_a_second_target() -> None:
    explorer, inspector = two_robots((0.0, 0.0, 0.7), (0.0, -8.0, 0.7))
    for mission in (explorer, inspector):
        car_in_view(mission.platform)  # type: ignore[arg-type]
        register_targets(mission.ctx, mission.ctx.capture())
    cars = explorer.graph.targets()
    assert len(cars) == 2
    assert abs(cars[0].position[1] - cars[1].position[1]) > explorer.params.d_check_T


def test_on_an_empty_site_the_inspector_waits_for_the_explorer_and_both_stop() -> None:
    explorer, inspector = two_robots((0.0, 0.0, 0.7), (0.0, 0.0, 0.7))
    steps: list[Activity] = []
    team = Team(explorer, inspector, on_step=steps.append)
    reason = team.execute()
    assert reason == (
        "explorer: no frontier left, then every target taken; inspector: every target taken"
    )
    waits = [s for s in steps if s.robot == "inspector" and s.activity == "wait"]
    assert waits and all(s.end > s.start for s in waits)
    assert inspector.platform.time == pytest.approx(explorer.platform.time)
    assert team.time == max(explorer.platform.time, inspector.platform.time)
    assert explorer.platform.frames > 0 and inspector.platform.frames == 0


def test_the_inspector_selects_by_eq6_from_its_own_pose() -> None:
    explorer, inspector = two_robots((0.0, 0.0, 0.7), (0.0, -8.0, 0.7))
    car_in_view(explorer.platform)  # type: ignore[arg-type]
    team = Team(explorer, inspector)
    team.explorer.step()  # the first survey registers the car, the graph's x_k is the explorer
    inspector.platform.wait(explorer.platform.time)  # level, so the car is known to both
    robot_at_selection = []
    select = inspector.select

    def watched_select(**kwargs):
        robot_at_selection.append(inspector.graph.robot.position.copy())
        return select(**kwargs)

    inspector.select = watched_select  # type: ignore[method-assign]
    step = team.inspector.step()
    np.testing.assert_allclose(robot_at_selection[0], (0.0, -8.0, 0.7))
    assert step.target is not None and step.activity in ("inspect", "skip")


def test_a_team_must_share_one_graph() -> None:
    ctx, _ = fake_context()
    explorer = XFlie(ctx.config, FakePlatform(), ctx.occupancy, ground_z=0.0)
    inspector = XFlie(ctx.config, FakePlatform(), ctx.occupancy, ground_z=0.0)
    with pytest.raises(InvalidInputError, match="share one graph"):
        Team(explorer, inspector)


def test_a_target_the_other_robot_held_at_this_clock_is_taken_only_after_its_release() -> None:
    explorer, inspector = two_robots((0.0, 0.0, 0.7), (0.0, -8.0, 0.7))
    car_in_view(explorer.platform)  # type: ignore[arg-type]
    team = Team(explorer, inspector)
    team.explorer.step()  # the first survey registers the car (seen ahead at every heading)
    car, *others = explorer.graph.targets()
    claims = explorer.graph.claims
    for target in (car, *others):
        claims.claim(target.id, "explorer", explorer.platform.time)
    explorer.platform.wait(500.0)
    claims.release(car.id, explorer.platform.time)  # the others stay taken
    waited = team.inspector.step()
    assert waited.activity == "wait" and waited.end == pytest.approx(explorer.platform.time)
    taken = team.inspector.step()
    assert taken.target == car.id and taken.start == pytest.approx(explorer.platform.time)
    assert [(c.target, c.robot) for c in claims.history if c.target == car.id] == [
        (car.id, "explorer"),
        (car.id, "inspector"),
    ]
    assert claims.history[-1].until == pytest.approx(inspector.platform.time)


def test_while_exploring_the_explorer_takes_only_targets_nearer_it_than_the_inspector() -> None:
    explorer, inspector = two_robots((0.0, 0.0, 0.7), (0.0, -3.0, 0.7))
    car_in_view(explorer.platform)  # type: ignore[arg-type]
    team = Team(explorer, inspector)
    team.explorer.step()  # the survey sees the car ahead at every heading: a ring of targets
    targets = explorer.graph.targets()
    inspectors = {t.id for t in targets if t.position[1] < -1.5}  # beyond the bisector
    assert inspectors and len(inspectors) < len(targets)
    pursuit = team.explorer.step()
    assert pursuit.target is not None and pursuit.target not in inspectors
    assert not team.explorer.explored


def test_once_exploration_is_done_the_explorer_takes_free_targets_by_eq6() -> None:
    explorer, inspector = two_robots((0.0, 0.0, 0.7), (0.0, 0.0, 0.7))
    car_in_view(explorer.platform)  # type: ignore[arg-type]
    # Where the explorer is, so no target is nearer the explorer while it explores; busy
    # until t = 1000 s, so every target is the explorer's to take once it is done.
    inspector.platform.wait(1000.0)
    steps: list[Activity] = []
    team = Team(explorer, inspector, on_step=steps.append)
    team.execute()
    pursuits = [s for s in steps if s.target is not None]
    explorer_steps = [s for s in steps if s.robot == "explorer"]
    assert [s.activity for s in explorer_steps[:2]] == ["survey", "explore"]
    assert pursuits and {s.robot for s in pursuits} == {"explorer"}
    assert min(s.start for s in pursuits) >= explorer_steps[1].end  # exploring came first
    claims = explorer.graph.claims.history
    assert [(c.target, c.robot) for c in claims] == [(s.target, "explorer") for s in pursuits]
    assert team.explorer.stop_reason.startswith("no frontier left, then ")
    inspected = [t.id for t in explorer.graph.targets() if t.inspected]
    assert team.explorer.inspected == [s.target for s in pursuits if s.activity == "inspect"]
    assert sorted(team.explorer.inspected) == sorted(inspected)


def test_a_target_seen_after_a_robots_clock_is_not_yet_known_to_it() -> None:
    explorer, inspector = two_robots((0.0, 0.0, 0.7), (0.0, -8.0, 0.7))
    car_in_view(explorer.platform)  # type: ignore[arg-type]
    explorer.platform.wait(100.0)  # its survey, one step, sees the car from t = 100 s on
    team = Team(explorer, inspector)
    team.explorer.step()
    assert explorer.graph.targets() and all(t.stamp >= 100.0 for t in explorer.graph.targets())
    waited = team.inspector.step()  # at t = 0 the inspector knows of no target yet
    assert waited.activity == "wait" and waited.end == pytest.approx(explorer.platform.time)
    taken = team.inspector.step()
    assert taken.target is not None


def on_a_corridor(explorer_at, inspector_at, settings=None, on_step=None) -> Team:
    """Two robots on one map known free for x in [-5, 5) m, unknown beyond: a frontier at
    each end."""
    ctx, _ = fake_context(settings=settings)
    states = ctx.occupancy.states
    states[:] = UNKNOWN
    states[10:30] = FREE
    explorer = XFlie(
        ctx.config, FakePlatform(explorer_at), ctx.occupancy, ground_z=0.0, name="explorer"
    )
    inspector = XFlie(
        ctx.config,
        FakePlatform(inspector_at),
        ctx.occupancy,
        ground_z=0.0,
        graph=explorer.graph,
        name="inspector",
    )
    return Team(explorer, inspector, on_step=on_step)


def test_with_no_free_target_the_inspector_explores_on_its_side_of_the_explorer() -> None:
    # The west frontier (x = -4.75) is the inspector's nearest, but nearer the explorer.
    team = on_a_corridor((-4.0, 0.0, 0.7), (-1.0, 0.0, 0.7))
    step = team.inspector.step()
    assert step.activity == "explore" and step.end > step.start
    (goal,) = team.inspector.mission.exploration.spent_frontiers
    assert goal[0] > 4.0  # the east one
    assert team.inspector.mission.platform.position[0] > 3.0
    assert team.inspector.hops == 1 and team.inspector.mission.platform.frames > 0


def test_once_the_explorer_has_stopped_exploring_the_inspector_takes_any_frontier() -> None:
    team = on_a_corridor((-4.0, 0.0, 0.7), (-1.0, 0.0, 0.7))
    team.explorer.explored = "no frontier left"
    assert team.inspector.step().activity == "explore"
    (goal,) = team.inspector.mission.exploration.spent_frontiers
    assert goal[0] < -4.0  # its nearest


def test_the_two_robots_share_one_frontier_hop_cap() -> None:
    team = on_a_corridor(
        (-4.0, 0.0, 0.7), (-1.0, 0.0, 0.7), {"exploration": {"frontier_max_hops": 2}}
    )
    team.explorer.hops = 2
    step = team.inspector.step()  # nothing to take, no hop left, the explorer not ahead
    assert step.activity == "stop" and team.inspector.hops == 0
    assert not team.inspector.mission.exploration.spent_frontiers


def test_the_team_stops_once_no_frontier_is_left_for_either_robot() -> None:
    steps: list[Activity] = []
    team = on_a_corridor((-4.0, 0.0, 0.7), (-1.0, 0.0, 0.7), on_step=steps.append)
    reason = team.execute()
    assert reason == (
        "explorer: no frontier left, then every target taken; inspector: every target taken"
    )
    assert ("inspector", "explore") in {(s.robot, s.activity) for s in steps}
    assert not find_frontiers(team.explorer.mission.occupancy, (0.3, 1.2), 12, 0.7)
    assert team.explorer.clock == pytest.approx(team.inspector.clock) == team.time


def test_an_explorer_that_misses_its_frontiers_explores_on_until_none_is_left() -> None:
    team = on_a_corridor((-1.0, 0.0, 0.7), (-1.0, 0.0, 0.7))
    explorer = team.explorer
    explorer.started = True  # its survey done; every route now fails
    explorer.mission.navigator.go_to = lambda *args, **kwargs: False  # type: ignore[method-assign]
    assert explorer.step().activity == "explore"
    assert len(explorer.mission.exploration.spent_frontiers) == 2  # both ends tried, missed
    assert explorer.exploring and not explorer.explored
    explorer.step()
    assert explorer.explored == "no frontier left" and explorer.hops == 0


def test_the_inspector_may_explore_a_frontier_the_explorer_has_spent() -> None:
    team = on_a_corridor((-4.0, 0.0, 0.7), (-1.0, 0.0, 0.7))
    team.explorer.mission.exploration.spent_frontiers.append(np.array([-4.75, 0.0, 0.7]))
    assert team.inspector.step().activity == "explore"
    (goal,) = team.inspector.mission.exploration.spent_frontiers
    assert goal[0] < -4.0  # the west end, its nearest, though nearer the explorer
