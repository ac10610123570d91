"""Speed of the 004 inspection environment against raw Embree on the same rays.

Two sets of rooms: ``train``, the training rooms of ``missions.learning.recipes`` (004 Sec
III-E: sizes drawn from [4, 20] x [4, 20] x [2, 8] m, cylinders, boxes and spheres, the
three-state ego map) and ``table1``, the evaluation rooms of Table I (10 x 10 x 4 m,
cylinders). Each has 9 obstacles, in training form (SAME_STEP autoreset, seed 0), for 1, 8 and
64 rooms stepped together, driven two ways:

* ``random``: uniform random actions (many crashes, so many room resets; the object is mostly
  out of view);
* ``orbit``: the orbit baseline, the "object in view" mode: it faces the object while circling
  it, as a trained policy does, so the camera pixels that may see it are cast too (about twice
  the rays of a room). ``in view`` reports the share of room-steps whose masked depth holds
  target pixels, so the mode is checked, not assumed;

with the ray casting and the map kernels on one thread and on two. Each row prints:

* env-steps/s: room-steps per second of ``InspectionVectorEnv.step``, observations included
  (dynamics, the camera and LiDAR rays, the robot's map, ego maps, rewards, resets);
* raw ms: one call of the rooms' ray caster (``worlds.raycast.RayCaster.cast``: Embree, the
  row's thread count) on the same ray batch (the rays the last step cast, built by
  ``missions.learning.sensors.sensor_rays``), measured in the same run: the floor a step
  cannot go below;
* env/raw: the step's time over that floor.

Target (issue 28): >= 2,500 env-steps/s with the object in view for 64 training rooms.

Run: ``.venv/bin/python bench/rl_env.py`` (about three minutes; ``--quick``: a smoke run of
1 and 8 rooms, a few seconds).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from seminspect.missions.learning.baselines import Controller, OrbitController, RandomController
from seminspect.missions.learning.env import EnvConfig, InspectionVectorEnv
from seminspect.missions.learning.evaluation import evaluation_config
from seminspect.missions.learning.recipes import policy_config, training_env_config
from seminspect.missions.learning.sensors import sensor_rays

#: Timed steps per room count: about the same number of room-steps for each.
STEPS = {1: 600, 8: 150, 64: 40}
#: Untimed steps first: the kernels compiled and, above all, the orbit turned to face the
#: object (it starts facing anywhere; 4 s in, about 95 % of its room-steps see it).
WARM_UP = 40
#: The rooms timed: the training rooms and Table I's evaluation rooms, 9 obstacles each.
ROOM_SETS = {
    "train": training_env_config(policy_config()).model_copy(update={"obstacles": 9}),
    "table1": evaluation_config(EnvConfig()).model_copy(update={"obstacles": 9}),
}


def step_rate(
    env: InspectionVectorEnv, controller: Controller, steps: int, warm_up: int
) -> tuple[float, float]:
    """Seconds per ``env.step`` (controller time excluded) over ``steps`` steps after
    ``warm_up`` untimed ones, and the share of room-steps whose masked depth shows the object."""
    obs, _ = env.reset(seed=0)
    controller.reset(env)
    for _ in range(warm_up):
        obs, *_ = env.step(controller.act(env, obs))
    spent, in_view = 0.0, 0.0
    for _ in range(steps):
        action = controller.act(env, obs)
        start = time.perf_counter()
        obs, *_ = env.step(action)
        spent += time.perf_counter() - start
        in_view += np.mean(obs["depth"].reshape(env.num_envs, -1).max(axis=1) > 0)
    return spent / steps, in_view / steps


def raw_cast_seconds(env: InspectionVectorEnv, repeats: int = 5) -> tuple[float, int]:
    """Median time of one cast of the rays the environment casts now, and their count."""
    shift = np.outer(np.arange(env.num_envs) * env._spacing, (1.0, 0.0, 0.0))
    target_box = np.stack([room.target_box for room in env.rooms]) + shift[:, None]
    _, _, starts, dirs = sensor_rays(
        env.positions() + shift,
        env.yaws(),
        env._camera,
        env._lidar,
        env._mapped,
        target_box,
        env.config.camera_range,
    )
    caster = env._caster
    assert caster is not None
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        caster.cast(starts, dirs, env.config.camera_range, env.threads)
        times.append(time.perf_counter() - start)
    return float(np.median(times)), len(dirs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--quick", action="store_true", help="a smoke run: 1 and 8 rooms, 2 steps, 3 warm-up"
    )
    args = parser.parse_args()
    print(f"{'set':>6} {'rooms':>5} {'policy':>6} {'threads':>7} {'env-steps/s':>12} "
          f"{'step ms':>8} {'in view':>7} {'rays':>7} {'raw ms':>7} {'env/raw':>7}")  # fmt: skip
    for name, config in ROOM_SETS.items():
        for rooms, full in STEPS.items():
            if args.quick and rooms > 8:
                continue
            steps, warm_up = (2, 3) if args.quick else (full, WARM_UP)
            controllers: dict[str, Controller] = {
                "random": RandomController(0),
                "orbit": OrbitController(),
            }
            for policy, controller in controllers.items():
                for threads in (1, 2):
                    env = InspectionVectorEnv(rooms, config, seed=0, threads=threads)
                    per_step, in_view = step_rate(env, controller, steps, warm_up)
                    raw, rays = raw_cast_seconds(env)
                    print(f"{name:>6} {rooms:>5} {policy:>6} {threads:>7} "
                          f"{rooms / per_step:>12,.0f} {per_step * 1e3:>8.2f} {in_view:>7.0%} "
                          f"{rays:>7,} {raw * 1e3:>7.2f} {per_step / raw:>7.1f}")  # fmt: skip


if __name__ == "__main__":
    main()
