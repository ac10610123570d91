"""Speed of the 004 inspection environment against raw Embree on the same rays.

For 1, 8 and 64 rooms stepped together (training form: SAME_STEP autoreset, 9 obstacles),
driven by random actions (many crashes, so many room resets) and by the orbit baseline (few),
with the ray casting on one thread and on two, each row prints:

* env-steps/s: room-steps per second of ``InspectionVectorEnv.step``, observations included
  (dynamics, the camera and LiDAR rays, the robot's map, ego maps, rewards, resets);
* raw ms: one call of the rooms' ray caster (``worlds.raycast.RayCaster.cast``: Embree, one
  thread) on the same ray batch (the rays the last step cast, built by
  ``missions.learning.sensors.sensor_rays``), the floor a step cannot go below;
* env/raw: the step's time over that floor.

Target (issue 12): >= 2,000 env-steps/s with 64 rooms.

Run: ``.venv/bin/python bench/rl_env.py`` (about a minute; ``--quick`` for a smoke run).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from seminspect.missions.learning.baselines import OrbitController, RandomController
from seminspect.missions.learning.env import EnvConfig, InspectionVectorEnv
from seminspect.missions.learning.sensors import sensor_rays

#: Timed steps per room count: about the same number of room-steps for each.
STEPS = {1: 600, 8: 150, 64: 40}


def step_rate(env: InspectionVectorEnv, controller, steps: int) -> float:
    """Seconds per ``env.step`` (controller time excluded) over ``steps`` steps."""
    obs, _ = env.reset(seed=0)
    controller.reset(env)
    for _ in range(3):  # warm-up: compiled kernels, first allocations
        obs, *_ = env.step(controller.act(env, obs))
    spent = 0.0
    for _ in range(steps):
        action = controller.act(env, obs)
        start = time.perf_counter()
        obs, *_ = env.step(action)
        spent += time.perf_counter() - start
    return spent / steps


def raw_cast_seconds(env: InspectionVectorEnv, repeats: int = 5) -> tuple[float, int]:
    """Median time of one cast of the rays the environment casts now, and their count."""
    every = np.arange(env.num_envs)
    rooms = env.rooms
    shift = np.outer(every * env._spacing, (1.0, 0.0, 0.0))
    target_centre = np.array([r.solids.centre[0] for r in rooms]) + shift
    target_size = np.array([r.solids.size[0] for r in rooms])
    _, _, starts, dirs = sensor_rays(
        env.positions() + shift,
        env.yaws(),
        env._camera,
        env._lidar,
        env._mapped,
        target_centre,
        target_size,
        env.config.camera_range,
    )
    caster = env._caster
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        caster.cast(starts, dirs, env.config.camera_range)
        times.append(time.perf_counter() - start)
    return float(np.median(times)), len(dirs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a tenth of the steps")
    args = parser.parse_args()
    config = EnvConfig(obstacles=9)
    print(f"{'rooms':>5} {'policy':>6} {'threads':>7} {'env-steps/s':>12} {'step ms':>8} "
          f"{'rays':>7} {'raw ms':>7} {'env/raw':>7}")  # fmt: skip
    for rooms, full in STEPS.items():
        steps = max(2, full // 10) if args.quick else full
        for name, controller in (("random", RandomController(0)), ("orbit", OrbitController())):
            for threads in (1, 2):
                env = InspectionVectorEnv(rooms, config, seed=0, threads=threads)
                per_step = step_rate(env, controller, steps)
                raw, rays = raw_cast_seconds(env)
                print(f"{rooms:>5} {name:>6} {threads:>7} {rooms / per_step:>12,.0f} "
                      f"{per_step * 1e3:>8.2f} {rays:>7,} {raw * 1e3:>7.2f} "
                      f"{per_step / raw:>7.1f}")  # fmt: skip


if __name__ == "__main__":
    main()
