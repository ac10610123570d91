"""How fast 002's adaptive planning runs: one planning cycle against 10 Hz, a mission against
real time.

* **Planning cycle**: ``plan_cycle`` (predict ``Π_LVP`` by eq (1), Fréchet distance, Γ_s,
  Kabsch) on the LiDAR cloud a robot sees 2 m from the receding face, cropped to the region,
  repeated; its median and
  99th percentile against the 100 ms a 10 Hz planner has, and the share each step takes. The
  Fréchet step is also timed in plain Python (the same recursion uncompiled) as its baseline.
* **Mission**: the whole receding mission (adaptive, seed 0, M_H recorded first) in simulated
  seconds per wall second.

Run: ``.venv/bin/python bench/routine.py [--repeats 200] [--horizon 3]``
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time

import numpy as np

from seminspect.geometry.paths import discrete_frechet, kabsch
from seminspect.mapping.voxel import VoxelMap
from seminspect.missions.routine.config import RoutineConfig
from seminspect.missions.routine.prior import LIDAR, make_robot
from seminspect.missions.routine.run import run_routine
from seminspect.missions.routine.tasks import default_tasks
from seminspect.planning.adaptive_cycle import plan_cycle, predict_local_path
from seminspect.planning.global_views import global_view_plan
from seminspect.worlds.routine_sites import mine_drift_site

BUDGET_MS = 100.0  # 10 Hz


def python_frechet(p: np.ndarray, q: np.ndarray) -> float:
    """Eiter-Mannila's table filled in plain Python: the uncompiled baseline."""
    n, m = len(p), len(q)
    table = [[0.0] * m for _ in range(n)]
    for i in range(n):
        for j in range(m):
            d = math.dist(p[i], q[j])
            if i == 0 and j == 0:
                table[i][j] = d
            elif i == 0:
                table[i][j] = max(table[i][j - 1], d)
            elif j == 0:
                table[i][j] = max(table[i - 1][j], d)
            else:
                table[i][j] = max(min(table[i - 1][j], table[i - 1][j - 1], table[i][j - 1]), d)
    return table[-1][-1]


def timed(function, repeats: int) -> np.ndarray:
    times = np.empty(repeats)
    for i in range(repeats):
        t0 = time.perf_counter()
        function()
        times[i] = 1e3 * (time.perf_counter() - t0)
    return times


def cycle_inputs(horizon: int):
    config = RoutineConfig(scenario="receding", seed=0, horizon=horizon)
    site = mine_drift_site("receding", 0)
    region = default_tasks(site)[0]
    prior = VoxelMap.from_world(site.historical, config.map_resolution)
    plan = global_view_plan(
        region,
        prior,
        config.view_constraints(),
        robot_radius=config.robot_radius,
        height_limits=config.z_limits,
        viewer=site.historical.start_position,
    )
    robot = make_robot(site.current, config)
    robot.move_to(plan.positions[0])
    cloud = LIDAR.scan(site.current, robot.position, robot.quaternion).points
    surface = cloud[region.contains(cloud, slab=3.0)]
    segment, yaws = plan.positions[:horizon], plan.yaws[:horizon]
    return config, robot.position, surface, segment, yaws, (region, cloud)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=200)
    parser.add_argument("--horizon", type=int, default=3)
    args = parser.parse_args()
    config, here, surface, segment, yaws, (region, cloud) = cycle_inputs(args.horizon)
    view = config.view_constraints()
    plan_cycle(here, surface, segment, yaws, view)  # compile once
    cycle = timed(lambda: plan_cycle(here, surface, segment, yaws, view), args.repeats)
    local = predict_local_path(here, surface, segment, yaws, view).positions
    predict = timed(lambda: predict_local_path(here, surface, segment, yaws, view), args.repeats)
    frechet = timed(lambda: discrete_frechet(segment, local), args.repeats)
    frechet_py = timed(lambda: python_frechet(segment, local), args.repeats)
    align = timed(lambda: kabsch(segment, local), args.repeats)
    crop = timed(lambda: region.contains(cloud, slab=3.0), args.repeats)
    print(
        f"planning cycle (N={args.horizon}, {len(surface)} of {len(cloud)} LiDAR points in the ROI)"
    )
    print(
        f"  median {np.median(cycle):.3f} ms, p99 {np.percentile(cycle, 99):.3f} ms: "
        f"{np.median(cycle) / BUDGET_MS:.4f} of the 100 ms a 10 Hz planner has"
    )
    speed_up = np.median(frechet_py) / np.median(frechet)
    print(
        f"  steps (median ms): predict {np.median(predict):.3f}, Fréchet {np.median(frechet):.4f} "
        f"(plain Python {np.median(frechet_py):.4f}, x{speed_up:.1f}), "
        f"Kabsch {np.median(align):.4f}; cropping the scan to the region "
        f"{np.median(crop):.3f} (not in the cycle: once per scan)"
    )
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        result = run_routine(RoutineConfig(scenario="receding", seed=0), f"{out}/run")
        wall = time.perf_counter() - t0
    m = result.metrics
    print(
        f"receding mission (M_H recorded first): {m.sim_time_s:.1f} s simulated in "
        f"{wall:.1f} s wall: {m.sim_time_s / wall:.1f}x real time"
    )


if __name__ == "__main__":
    main()
