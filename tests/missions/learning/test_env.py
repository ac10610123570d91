"""The 004 environment: the ego frame, determinism, the pruned camera rays, the env checker."""

import math

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from seminspect.geometry.transforms import rotate_xy
from seminspect.missions.learning.env import EnvConfig, InspectionEnv, InspectionVectorEnv
from seminspect.missions.learning.sensors import camera_rays, sensor_rays


@pytest.fixture(scope="module")
def empty_room_env():
    env = InspectionVectorEnv(1, EnvConfig(obstacles=0), seed=0, autoreset=False)
    env.reset(seed=0)
    return env


def test_the_ego_map_is_rotated_into_the_body_frame(empty_room_env):
    env = empty_room_env
    env._occupancy[0] = 0
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


def test_two_ray_threads_give_the_same_results(monkeypatch):
    # make sure the rays really are split over the threads
    monkeypatch.setattr("seminspect.worlds.raycast.MIN_RAYS_PER_THREAD", 64)
    assert _same(_rollout(3, threads=1, envs=3), _rollout(3, threads=2, envs=3))


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
        room.solids.centre[:1],
        room.solids.size[:1],
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
