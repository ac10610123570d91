"""The learned policy beside xFLIE: the room as a World, the replay through the 004 camera,
the new environment entry points it uses, and the study's curves and table."""

from __future__ import annotations

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.core.rng import make_rng
from seminspect.missions.learning.agent import load_controller
from seminspect.missions.learning.env import InspectionVectorEnv
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.feasibility import feasible_faces
from seminspect.missions.learning.rooms import Room, sample_room
from seminspect.studies.learning import versus_xflie as vx
from seminspect.worlds.world import GROUND

#: No noise anywhere: a robot at rest then sees exactly the same in every step.
QUIET = EnvConfig(
    obstacles=4, disturbance_std=0.0, state_noise=0.0, depth_noise=(0.0, 0.0), episode_seconds=5
)


@pytest.fixture(scope="module")
def room() -> Room:
    drawn = vx.shared_start(sample_room(make_rng(3, "test-versus"), 4, QUIET))
    assert drawn is not None
    return drawn


def test_observe_at_rest_equals_a_step_without_action(room: Room) -> None:
    stepped = InspectionVectorEnv(1, QUIET, autoreset=False)
    placed = InspectionVectorEnv(1, QUIET, autoreset=False)
    stepped.reset(options={"rooms": [room]})
    placed.reset(options={"rooms": [room]})
    assert stepped.rooms[0] is room
    for _ in range(3):
        by_step = stepped.step(np.zeros((1, 4)))[0]
        by_pose = placed.observe_at(room.start[None], np.array([room.start_yaw]))
        for key, value in by_step.items():
            np.testing.assert_array_equal(by_pose[key], value, err_msg=key)
    np.testing.assert_array_equal(placed.strict_seen(), stepped.strict_seen())
    np.testing.assert_array_equal(placed.face_distances(0), stepped.face_distances(0))
    assert np.isfinite(placed.face_distances(0)).any()  # it saw the object at all


def test_observe_at_moves_the_robot_and_refuses_bad_poses(room: Room) -> None:
    env = InspectionVectorEnv(1, QUIET, autoreset=False)
    with pytest.raises(InvalidInputError, match="reset"):
        env.observe_at(room.start[None], np.zeros(1))
    env.reset(options={"rooms": [room]})
    env.observe_at([[2.0, 3.0, 1.5]], [4.0])
    np.testing.assert_allclose(env.positions(), [[2.0, 3.0, 1.5]])
    np.testing.assert_allclose(env.yaws(), [4.0 - 2 * np.pi])  # wrapped into [-pi, pi)
    with pytest.raises(InvalidInputError, match=r"\(1, 3\) positions"):
        env.observe_at(room.start, np.zeros(1))
    with pytest.raises(InvalidInputError, match="finite"):
        env.observe_at([[np.nan, 1.0, 1.0]], [0.0])


def test_reset_refuses_rooms_that_do_not_fit(room: Room) -> None:
    env = InspectionVectorEnv(2, QUIET)
    with pytest.raises(InvalidInputError, match="2 Room objects"):
        env.reset(options={"rooms": [room]})
    small = InspectionVectorEnv(1, QUIET.model_copy(update={"room_size": (8.0, 10.0, 4.0)}))
    with pytest.raises(InvalidInputError, match="exceeds the largest"):
        small.reset(options={"rooms": [room]})


def test_the_world_holds_the_rooms_target_as_one_instance(room: Room) -> None:
    world = vx.room_world(room)
    (pipe,) = world.instances_of(vx.TARGET_CLASS)
    on_target = room.face_of_triangle >= 0
    np.testing.assert_array_equal(
        world.triangles[world.face_instance == pipe.id],
        room.vertices[room.triangles[on_target]],
    )
    assert len(world.mesh.faces) == len(room.triangles)
    floor = world.triangles[world.face_class == world.class_id(GROUND)]
    assert len(floor) == 2 and np.all(floor[..., 2] == 0.0)
    np.testing.assert_allclose(world.bounds, [np.zeros(3), room.size])
    assert world.start_position[2] == 0.0  # xFLIE takes off from the floor below the start


def test_shared_start_is_level_with_the_object_within_xflies_band(room: Room) -> None:
    middle = room.target_box[:, 2].mean()
    expected = min(max(middle, vx.XFLIE_LOWEST), room.size[2] - vx.XFLIE_LOWEST)
    assert room.start[2] == pytest.approx(expected)
    config = vx.xflie_config(room, QUIET, 90.0, 0, "ideal")
    assert config.robot.flight_height == room.start[2]
    assert config.inspection is not None and config.inspection.d_view == QUIET.d_ref


def test_resample_interpolates_the_unwrapped_yaw_and_holds_the_end() -> None:
    rows = np.array([[0.0, 0.0, 0.0, 1.0, 3.0], [2.0, 2.0, 0.0, 1.0, 3.4]])
    poses = vx.resample(rows, np.array([0.0, 1.0, 3.0]))
    np.testing.assert_allclose(poses, [[0, 0, 1, 3.0], [1, 0, 1, 3.2], [2, 0, 1, 3.4]])


def test_a_parked_flight_replays_as_the_environment_sees_its_start(room: Room) -> None:
    rows = np.array([[0.0, *room.start, room.start_yaw], [2.0, *room.start, room.start_yaw]])
    flown = vx.replay_xflie([room], [vx.XFlieFlight(rows, "")], QUIET, seconds=3)
    env = InspectionVectorEnv(1, QUIET, autoreset=False)
    env.reset(options={"rooms": [room]})
    assert flown.seen.shape == (1, 4, 60)
    for second in range(4):
        np.testing.assert_array_equal(flown.seen[0, second], env.strict_seen()[0])
    assert not flown.crashed[0] and flown.ended_s[0] == 2.0


def test_a_flight_through_an_obstacle_crashes_and_stops_counting(room: Room) -> None:
    inside = room.solids.centre[room.target_solids]  # an obstacle's centre
    rows = np.array([[0.0, *room.start, 0.0], [4.0, *inside, 0.0]])
    flown = vx.replay_xflie([room], [vx.XFlieFlight(rows, "")], QUIET, seconds=5)
    assert flown.crashed[0] and flown.ended_s[0] < 4.0
    after = int(np.ceil(flown.ended_s[0]))
    assert after < 5 and np.all(flown.seen[0, after:] == flown.seen[0, -1])  # held after it


def test_the_policys_curves_rise_within_0_and_100(room: Room) -> None:
    controller = load_controller()
    quiet = QUIET.model_dump(include={"disturbance_std", "state_noise", "depth_noise"})
    config = controller.env_config.model_copy(update=quiet)  # what it was trained in
    flown = vx.fly_policy([room, room], controller, config, seconds=3)
    curves = vx.strict_curves(flown, feasible_faces(room, config)[None].repeat(2, axis=0))
    assert curves.shape == (2, 4)
    assert np.all((curves >= 0) & (curves <= 100)) and np.all(np.diff(curves, axis=1) >= 0)
    np.testing.assert_array_equal(curves[0], curves[1])  # the same room, the same flight


def _result(learned: list[list[float]], xflie: list[list[float]]) -> vx.VersusResult:
    rooms = len(learned)
    return vx.VersusResult(
        curves={"learned": np.array(learned), "xflie": np.array(xflie)},
        crashed={
            "learned": np.array([True] + [False] * (rooms - 1)),
            "xflie": np.zeros(rooms, dtype=bool),
        },
        ended_s={"learned": np.full(rooms, 2.0), "xflie": np.full(rooms, 2.0)},
        shapes=["cylinder", "box"][:rooms],
        feasible=[48] * rooms,
        stop_reasons=[""] * rooms,
        skipped=0,
        wall_s={"learned": 1.0, "xflie": 1.0},
    )


def test_time_to_a_level_and_the_table() -> None:
    result = _result([[0, 60, 90], [0, 10, 40]], [[0, 0, 50], [0, 0, 0]])
    np.testing.assert_array_equal(vx.time_to(result.curves["learned"], 50.0), [1, np.inf])
    table = vx.versus_markdown(result, at_s=1)
    rows = {tuple(c.strip() for c in line.split("|")[1:3]): line for line in table.splitlines()}
    assert "1 s (1/2)" in rows[("learned", "all")]  # time to 50 %: the rooms that got there
    assert "- (0/2)" in rows[("xflie", "all")]  # nobody reached 80 %
    assert rows[("learned", "all")].endswith("| 1 |")  # one crash
    assert ("xflie", "box") in rows  # a row per shape when there are several
    figure = vx.versus_figure(result)
    assert len(figure.axes[0].lines) == 4  # two planners, two marks


def test_xflie_flies_the_room_from_the_shared_start(room: Room) -> None:
    flight = vx.fly_xflie(room, QUIET, seconds=75.0, seed=0, noise="ideal")
    t, position, yaw = flight.trajectory[:, 0], flight.trajectory[:, 1:4], flight.trajectory[:, 4]
    np.testing.assert_allclose(position[0], room.start)
    assert yaw[0] == pytest.approx(room.start_yaw) and np.all(np.diff(t) >= 0)
    assert t[-1] > 0.0 and flight.stop_reason  # (xFLIE may finish a level past its budget)
    assert np.ptp(position, axis=0).max() > 0.3  # it moved: a survey alone only turns
    assert np.all((position > 0) & (position < room.size))
