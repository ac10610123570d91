"""Reference controllers: the seeded random policy and the semantic orbit."""

import numpy as np
import pytest

from seminspect.missions.learning.baselines import OrbitController, RandomController
from seminspect.missions.learning.env import EnvConfig, InspectionVectorEnv
from seminspect.missions.learning.env_config import TARGET_SHAPES
from seminspect.missions.learning.evaluation import evaluate


def test_random_actions_are_in_range_and_restart_with_reset():
    env = InspectionVectorEnv(3, EnvConfig(obstacles=0), autoreset=False)
    obs, _ = env.reset(seed=0)
    policy = RandomController(seed=5)
    policy.reset(env)
    first = policy.act(env, obs)
    assert first.shape == (3, 4) and np.all(np.abs(first) <= 1.0)
    assert not np.array_equal(first, policy.act(env, obs))
    policy.reset(env)
    np.testing.assert_array_equal(first, policy.act(env, obs))


def test_the_orbit_heads_for_the_target_and_faces_it():
    env = InspectionVectorEnv(1, EnvConfig(obstacles=0), autoreset=False)
    obs, _ = env.reset(seed=1)
    orbit = OrbitController()
    orbit.reset(env)
    target = env.rooms[0].target_box.mean(axis=0)
    for _ in range(60):
        obs, *_ = env.step(orbit.act(env, obs))
    offset = target[:2] - env.positions()[0, :2]
    bearing = np.arctan2(offset[1], offset[0]) - env.yaws()[0]
    assert abs(np.angle(np.exp(1j * bearing))) < 0.5  # looking at the target
    radius = env.rooms[0].target_radius + env.config.d_ref
    assert abs(np.linalg.norm(offset) - radius) < 0.5


def test_the_orbit_covers_more_than_random_in_empty_rooms():
    config = EnvConfig(episode_seconds=30.0)
    runs = {
        name: evaluate(controller, [0], 3, seed=2, config=config, num_envs=3)
        for name, controller in {"orbit": OrbitController(), "random": RandomController()}.items()
    }
    orbit, random = runs["orbit"].at(0), runs["random"].at(0)
    assert orbit.coverage_pct > random.coverage_pct + 30.0
    assert min(orbit.coverage) > max(random.coverage)


@pytest.mark.parametrize("shape", TARGET_SHAPES)
def test_the_orbit_inspects_every_shape_in_an_empty_room(shape):
    config = EnvConfig(obstacles=0, target_shapes=(shape,), episode_seconds=40.0)
    env = InspectionVectorEnv(1, config, autoreset=False)
    obs, _ = env.reset(seed=0)
    assert env.rooms[0].shape == shape
    orbit = OrbitController()
    orbit.reset(env)
    heights = []
    for _ in range(config.steps_per_episode):
        obs, _, crash, _, _ = env.step(orbit.act(env, obs))
        assert not crash.any()
        heights.append(env.positions()[0, 2])
    assert env.coverage()[0] > 0.8
    top = env.rooms[0].target_box[1, 2]
    assert max(heights) > top + 0.3  # the second loop passes over the top
