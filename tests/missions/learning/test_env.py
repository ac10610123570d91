"""The 004 environment: the ego frame, determinism, the pruned camera rays, the env checker,
and what the policy sees and is paid: penalties, crashes, the focus area, coverage, the
three-state map, the heading and the fraction reward."""

import math

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from seminspect.geometry.transforms import rotate_xy
from seminspect.missions.learning.baselines import OrbitController
from seminspect.missions.learning.env import EnvConfig, InspectionVectorEnv
from seminspect.missions.learning.face_views import triangle_normals
from seminspect.missions.learning.maps import FREE, OCCUPIED
from seminspect.missions.learning.sensors import camera_rays, sensor_rays
from seminspect.missions.learning.single_env import InspectionEnv
from seminspect.missions.learning.solids import solid_distance

#: Still rooms: no disturbance, no state noise, so hand-placed robots stay where they are put.
QUIET = {"obstacles": 0, "disturbance_std": 0.0, "state_noise": 0.0}


@pytest.fixture(scope="module")
def empty_room_env():
    env = InspectionVectorEnv(1, EnvConfig(obstacles=0), seed=0, autoreset=False)
    env.reset(seed=0)
    return env


@pytest.fixture(scope="module")
def paper_env():
    env = InspectionVectorEnv(1, EnvConfig(**QUIET), seed=0, autoreset=False)
    env.reset(seed=0)
    return env


@pytest.fixture(scope="module")
def legacy_env():
    env = InspectionVectorEnv(1, EnvConfig.legacy(**QUIET), seed=0, autoreset=False)
    env.reset(seed=0)
    return env


def test_the_ego_map_is_rotated_into_the_body_frame(empty_room_env):
    env = empty_room_env
    env._occupancy[0] = FREE
    env._position[0] = (5.05, 5.05, 2.05)  # a cell centre, so the lookups are unambiguous
    env._yaw[0] = math.pi / 2  # body x (forward) = world +y, body y (left) = world -x
    env._occupancy[0, 20, 53, 50] = 1  # world +0.3 m in y: 3 cells ahead
    env._occupancy[0, 20, 50, 48] = 1  # world -0.2 m in x: 2 cells to the left
    env._fill_maps(np.array([0]))
    ego = env._obs["maps"][0, 0]  # (z, y, x), the robot in cell (10, 10, 10)
    assert ego[10, 10, 13] == 1 and ego[10, 12, 10] == 1
    assert ego.sum() == 2


def _rollout(seed: int, steps: int = 4, threads: int = 1, envs: int = 2):
    env = InspectionVectorEnv(envs, EnvConfig(obstacles=4), seed=seed, threads=threads)
    obs, _ = env.reset(seed=seed)
    frames, rewards = [obs], []
    actions = np.tile(np.array([0.6, 0.2, -0.1, 0.5], dtype=np.float32), (envs, 1))
    for _ in range(steps):
        obs, reward, *_ = env.step(actions)
        frames.append(obs)
        rewards.append(reward)
    return frames, np.array(rewards)


def _same(a, b) -> bool:
    frames_a, rewards_a = a
    frames_b, rewards_b = b
    same_obs = all(
        np.array_equal(x[key], y[key]) for x, y in zip(frames_a, frames_b, strict=True) for key in x
    )
    return same_obs and np.array_equal(rewards_a, rewards_b)


def test_the_same_seed_gives_the_same_observations_and_rewards():
    first = _rollout(7)
    assert _same(first, _rollout(7))
    assert not _same(first, _rollout(8))


def test_two_threads_give_the_same_results(monkeypatch):
    # the rays really split over the threads, and 5 rooms split the rooms' kernels (the
    # rays, the map updates, the ego maps) into blocks, some empty
    monkeypatch.setattr("seminspect.worlds.raycast.MIN_RAYS_PER_THREAD", 64)
    assert _same(_rollout(3, threads=1, envs=5), _rollout(3, threads=2, envs=5))


def test_the_single_env_passes_the_gymnasium_checker():
    check_env(InspectionEnv(EnvConfig(obstacles=4)), skip_render_check=True)


def test_masked_depth_is_the_full_render_on_target_pixels_only(empty_room_env):
    env = empty_room_env
    cfg = env.config
    room = env.rooms[0]
    centre, radius = room.solids.centre[0], room.solids.size[0, 0]
    env._position[0] = centre + np.array([radius + cfg.d_ref, 0.0, 0.0])
    env._yaw[0] = math.pi  # facing the target along -x
    env._sense(np.array([0]))
    depth = env._obs["depth"][0, 0].reshape(-1)
    # every pixel cast by hand
    camera, cosines = camera_rays(cfg.image_size, cfg.fov_deg)
    turned = rotate_xy(math.cos(env._yaw[0]), math.sin(env._yaw[0]), camera[:, 0], camera[:, 1])
    world = np.column_stack([*turned, camera[:, 2]])
    distance, tri = env._caster.cast(env._position[0], world, cfg.camera_range)
    on_target = (tri >= 0) & (env._face_of_triangle[np.maximum(tri, 0)] >= 0)
    assert on_target.sum() > 100  # the target fills part of the view
    np.testing.assert_array_equal(depth > 0, on_target)
    expected = distance[on_target] * cosines[on_target] / cfg.camera_range
    np.testing.assert_allclose(depth[on_target], expected, atol=0.02)  # range noise only
    # the pruned ray set keeps every target pixel
    _, ray, _, _ = sensor_rays(
        env._position[:1],
        env._yaw[:1],
        env._camera,
        env._lidar,
        env._mapped,
        room.target_box[None],
        cfg.camera_range,
    )
    kept = ray[ray < len(camera)]
    assert set(np.flatnonzero(on_target)) <= set(kept.tolist())
    assert len(kept) < len(camera)  # and it does prune


def test_stepping_after_every_room_ended_changes_nothing():
    env = InspectionVectorEnv(2, EnvConfig(obstacles=0, episode_seconds=0.2), autoreset=False)
    env.reset(seed=3)
    for _ in range(2):
        env.step(np.zeros((2, 4), dtype=np.float32))
    before = env.positions()
    _, reward, crash, timeout, _ = env.step(np.ones((2, 4), dtype=np.float32))
    assert np.array_equal(env.positions(), before)
    assert not reward.any() and not crash.any() and not timeout.any()


def test_rooms_that_run_on_alone_see_their_own_maps():
    """When earlier rooms have ended, the later ones must keep sampling their own maps.

    Two copies of the same batch: in one, room 0 ends at once (a 0.1 s episode would end all,
    so it is frozen by hand); room 1's observations must match the copy where both run.
    """
    config = EnvConfig(obstacles=4)
    both = InspectionVectorEnv(3, config, autoreset=False)
    alone = InspectionVectorEnv(3, config, autoreset=False)
    both.reset(seed=8)
    alone.reset(seed=8)
    alone._done[0] = True  # room 0 has ended: only rooms 1 and 2 are stepped
    actions = np.tile(np.array([[0.3, 0.2, 0.0, 0.4]], dtype=np.float32), (3, 1))
    for _ in range(5):
        obs_both, reward_both, *_ = both.step(actions)
        obs_alone, reward_alone, *_ = alone.step(actions)
    for key in ("state", "depth", "maps"):
        assert np.array_equal(obs_both[key][1:], obs_alone[key][1:]), key
    assert np.array_equal(reward_both[1:], reward_alone[1:])


def _place(env, position, yaw=0.0) -> None:
    env._position[0], env._yaw[0] = position, yaw
    env._velocity[0], env._yaw_rate[0] = 0.0, 0.0


@pytest.mark.parametrize(
    ("cells_ahead", "binary", "graded"),
    [(2, -1.0, -1.0), (4, 0.0, -2.0 / 3.0), (5, 0.0, -1.0 / 3.0), (7, 0.0, 0.0)],
)
def test_the_collision_penalty_at_chosen_distances(
    paper_env, legacy_env, cells_ahead, binary, graded
):
    """d_coll 0.3 m, penalty_reach 0.6 m; one occupied cell 0.1 m x ``cells_ahead`` ahead."""
    for env, expected in ((legacy_env, binary), (paper_env, graded)):
        _place(env, (5.05, 5.05, 2.05))  # a cell centre, so the distances are exact
        env._occupancy[0] = FREE
        env._occupancy[0, 20, 50, 50 + cells_ahead] = OCCUPIED
        _, penalty = env._fill_maps(np.array([0]))
        assert penalty[0] == pytest.approx(expected), env.config.proximity_penalty


def test_the_contact_penalty_reads_the_velocity_in_the_ego_maps_frame():
    """A cell 0.8 m along +y of the room, the robot facing +y (yaw pi/2) and moving at 1.2
    m/s toward it: 0.6 m of gap, contact in 0.5 s, so -0.5 with a 1 s horizon (the graded
    penalty reads 0 beyond 0.6 m); moving along x instead, nothing."""
    env = InspectionVectorEnv(1, EnvConfig(**QUIET, proximity_penalty="contact"), seed=0)
    env.reset(seed=0)
    for velocity, expected in (((0.0, 1.2, 0.0), -0.5), ((1.2, 0.0, 0.0), 0.0)):
        _place(env, (5.05, 5.05, 2.05), yaw=math.pi / 2)
        env._velocity[0] = velocity
        env._occupancy[0] = FREE
        env._occupancy[0, 20, 58, 50] = OCCUPIED
        _, penalty = env._fill_maps(np.array([0]))
        assert penalty[0] == pytest.approx(expected, abs=1e-9), velocity


@pytest.mark.parametrize(("gap", "crashed"), [(-0.005, True), (0.005, False)])
def test_a_crash_is_a_clearance_below_the_robot_radius(monkeypatch, gap, crashed):
    env = InspectionVectorEnv(1, EnvConfig(**QUIET), seed=0, autoreset=False)
    env.reset(seed=0)
    room = env.rooms[0]
    # near the x = 0 wall, level with the target's middle but on the far side of the room
    target_y = room.solids.centre[0, 1]
    y = 8.0 if target_y < 5.0 else 2.0
    _place(env, (env.config.robot_radius + gap, y, 2.0))
    monkeypatch.setattr(env, "_sense", lambda envs: np.zeros(len(envs)))  # the crash term only
    _, reward, crash, timeout, info = env.step(np.zeros((1, 4), dtype=np.float32))
    assert crash[0] == crashed and not timeout[0]
    assert reward[0] == pytest.approx(-env.config.crash_penalty if crashed else 0.0)
    assert ("episode" in info) == crashed


@pytest.mark.parametrize(("gap", "crashed"), [(-0.005, True), (0.005, False)])
def test_a_robot_crashes_by_its_own_smaller_rooms_walls(monkeypatch, gap, crashed):
    """Rooms drawn 4-5 m wide: the far wall is the room's own, not room_size's 10 m."""
    small = ((4.0, 5.0), (4.0, 5.0), (2.0, 3.0))
    env = InspectionVectorEnv(1, EnvConfig(**QUIET, room_size_range=small), seed=0)
    env.reset(seed=0)
    room = env.rooms[0]
    assert room.size[0] < 5.0 + 1e-9
    target_y = room.solids.centre[0, 1]
    y = room.size[1] - 1.0 if target_y < room.size[1] / 2 else 1.0  # away from the object
    position = np.array([room.size[0] - env.config.robot_radius - gap, y, room.size[2] / 2])
    assert solid_distance(position[None], room.solids)[0] > 0.5  # only the wall is near
    _place(env, position)
    monkeypatch.setattr(env, "_sense", lambda envs: np.zeros(len(envs)))  # the crash term only
    _, _, crash, _, _ = env.step(np.zeros((1, 4), dtype=np.float32))
    assert crash[0] == crashed


def _face_a_facet(env: InspectionVectorEnv, distance: float) -> int:
    """Put the robot ``distance`` before the target's side face nearest its mid height, facing
    it head-on; returns the face."""
    room = env.rooms[0]
    normals = triangle_normals(room.vertices, room.triangles)
    centroid = room.vertices[room.triangles].mean(axis=1)
    side = np.flatnonzero((room.face_of_triangle >= 0) & (np.abs(normals[:, 2]) < 1e-6))
    tri = side[np.argmin(np.abs(centroid[side, 2] - room.target_box.mean(axis=0)[2]))]
    face = room.face_of_triangle[tri]
    middle = centroid[room.face_of_triangle == face].mean(axis=0)
    _place(env, middle + distance * normals[tri], math.atan2(-normals[tri, 1], -normals[tri, 0]))
    return int(face)


def _facing_a_facet(config: EnvConfig, distance: float) -> tuple[InspectionVectorEnv, int]:
    env = InspectionVectorEnv(1, config, seed=0, autoreset=False)
    env.reset(seed=0)
    face = _face_a_facet(env, distance)
    env._sense(np.array([0]))
    return env, face


def test_a_face_seen_outside_the_focus_area_earns_nothing_and_is_not_strictly_seen(monkeypatch):
    seen, face = _facing_a_facet(EnvConfig(**QUIET), 1.5)  # the control: the usual focus area
    assert seen.strict_seen()[0, face] and seen.distance_scores()[0, face] > 0.99
    target = seen._obs["depth"][0, 0].reshape(-1) > 0
    env = InspectionVectorEnv(1, EnvConfig(**QUIET), seed=0, autoreset=False)
    env.reset(seed=0)
    monkeypatch.setattr(env, "_focus", ~target)  # a focus area away from every target pixel
    _face_a_facet(env, 1.5)
    reward = env._sense(np.array([0]))
    assert (env._obs["depth"][0, 0] > 0).sum() == target.sum() > 100  # in view all the same
    v_t, p_t = env._fill_maps(np.array([0]))  # as in that _sense: the same visits and map
    assert reward - v_t[0] - p_t[0] == pytest.approx(0.0, abs=1e-12)  # no f_t
    assert not env.strict_seen().any() and not env.distance_scores().any()
    assert env.coverage()[0] == 0.0


@pytest.mark.parametrize(
    ("changes", "strict"),
    [
        ({}, True),
        ({"strict_incidence_deg": 1.0}, False),  # facet pixels are a few degrees off its normal
        ({"strict_min_pixels": 5000}, False),
        ({"d_ref": 2.5}, False),  # seen from 1.5 m, outside 2.5 +- 0.5
    ],
)
def test_each_strict_condition_can_reject_a_head_on_view(changes, strict):
    env, face = _facing_a_facet(EnvConfig(**QUIET | changes), 1.5)
    assert env.strict_seen()[0, face] == strict
    assert env.coverage()[0] > 0  # the lenient rule: seen within inspect_range


def test_rays_carve_free_space_and_unseen_cells_stay_unknown(paper_env, legacy_env):
    for env, stale in ((paper_env, 0.0), (legacy_env, 1.0)):
        env._occupancy[0] = 0
        _place(env, (5.05, 5.05, 2.05))
        env._occupancy[0, 20, 50, 55] = OCCUPIED  # 0.5 m ahead: a stale noise hit
        env._sense(np.array([0]))
        ego = env._obs["maps"][0, 0]  # (z, y, x), the robot in cell (10, 10, 10)
        assert ego[10, 10, 15] == stale, env.config.ego_map
    # above the robot, beyond the LiDAR's 45 deg and the camera's 29: never reached
    assert ego[18, 10, 10] == 0.0  # binary: unknown reads free
    ego = paper_env._obs["maps"][0, 0]
    assert ego[18, 10, 10] == 0.5 and ego[10, 10, 10] == 0.0
    assert set(np.unique(ego)) <= {0.0, 0.5, 1.0}
    # the returns' cells stay occupied (carving first); carved last, each ray clears its own
    assert np.count_nonzero(paper_env._occupancy[0] == OCCUPIED) > 300


def test_the_full_angle_heading_is_continuous_at_pi_and_the_half_angle_flips(paper_env, legacy_env):
    for env in (paper_env, legacy_env):
        states = []
        for yaw in (math.pi - 1e-4, -math.pi + 1e-4):
            env._yaw[0] = yaw
            env._fill_state(np.array([0]))
            states.append(env._obs["state"][0, [3, 6]].copy())
        if env.config.yaw_encoding == "full-angle":
            np.testing.assert_allclose(states[0], states[1], atol=1e-3)
            np.testing.assert_allclose(states[0], [-1.0, 0.0], atol=1e-3)
        else:  # (cos yaw/2, sin yaw/2): sin jumps from +1 to -1
            np.testing.assert_allclose(states[0], [0.0, 1.0], atol=1e-3)
            np.testing.assert_allclose(states[1], [0.0, -1.0], atol=1e-3)


def test_the_fraction_reward_is_the_distance_weighted_fraction_seen_so_far(monkeypatch):
    env = InspectionVectorEnv(1, EnvConfig(obstacles=0), seed=2, autoreset=False)
    obs, _ = env.reset(seed=2)
    paid: list[float] = []
    levels: list[float] = []
    update = env._faces.update

    def record(envs, views):
        f_t = update(envs, views)
        paid.append(float(f_t[0]))
        levels.append(float(env.distance_scores()[0].mean()))
        return f_t

    monkeypatch.setattr(env._faces, "update", record)
    orbit = OrbitController()
    orbit.reset(env)
    for _ in range(80):
        obs, *_ = env.step(orbit.act(env, obs))
    np.testing.assert_allclose(paid, levels, rtol=1e-12)
    assert paid == sorted(paid)  # what was inspected stays inspected
    assert 0.2 < paid[-1] <= 1.0  # the orbit sees a good part of the target


def test_the_shaped_reward_is_the_streams_increment_and_a_crash_forfeits_it():
    discount, rooms = 0.99, 8
    shaped_config = EnvConfig(obstacles=9, shaping_discount=discount)
    plain = InspectionVectorEnv(rooms, EnvConfig(obstacles=9), seed=4, autoreset=False)
    shaped = InspectionVectorEnv(rooms, shaped_config, seed=4, autoreset=False)
    plain.reset(seed=4)
    shaped.reset(seed=4)
    before = shaped.distance_scores().mean(axis=1)  # f_0, the reset's view
    actions = np.random.default_rng(4).uniform(-1.0, 1.0, (120, rooms, 4)).astype(np.float32)
    crashes = 0
    for action in actions:
        live = ~shaped._done
        _, plain_reward, _, _, _ = plain.step(action)
        _, shaped_reward, crash, _, _ = shaped.step(action)
        f_t = shaped.distance_scores().mean(axis=1)
        expected = plain_reward + np.where(live, (f_t - before) / (1 - discount) - f_t, 0.0)
        expected -= np.where(crash, discount * f_t / (1 - discount), 0.0)
        np.testing.assert_allclose(shaped_reward, expected, rtol=1e-5, atol=1e-4)
        before, crashes = f_t, crashes + int(crash.sum())
    assert crashes > 0  # the crash term was exercised
