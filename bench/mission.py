"""How fast a mission runs: simulated seconds per wall second, and where the wall time goes.

Runs one full xFLIE mission (default: city large, 20 vehicles, seed 0, realistic noise, no
pictures) and prints the real-time factor against its target (20x for city large, 50x for city
medium, the default mission; none for other missions), the wall time per
category (sensing: rendering, LiDAR and map updates; perception: segmentation, localisation,
feature matching; graph: 3DLSG operators; planning: hierarchical, local and view planning and
map queries; driving: the simulated motion) and the counts behind them.

Run: ``.venv/bin/python bench/mission.py [--scenario large] [--seed 0] [--profile]``
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import tempfile
import time

from mission_profile import outcome
from seminspect.missions.xflie.config import make_config
from seminspect.missions.xflie.run import run_mission

#: Real-time factors the benchmarked missions must reach: city large since the first speed
#: work, city medium (the default mission, first run after install included) since issue 16.
TARGET_FACTORS = {("city", "large"): 20.0, ("city", "medium"): 50.0}


def target_verdict(factor: float, target: float | None) -> str:
    """`` (target 20x: met)``, or nothing for a mission without a target."""
    if target is None:
        return ""
    return f" (target {target:.0f}x: {'met' if factor >= target else 'missed'})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--world", default="city")
    parser.add_argument("--scenario", default="large")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--carving-spacing", type=float, help="thinned free-space carving (cells; default exact)"
    )
    parser.add_argument("--profile", action="store_true", help="also print the top functions")
    args = parser.parse_args()

    settings = {"world": args.world, "scenario": args.scenario, "seed": args.seed}
    if args.carving_spacing is not None:  # left out otherwise: the script also runs older code
        settings["map_carving_spacing"] = args.carving_spacing
    config = make_config(settings)
    profiler = cProfile.Profile() if args.profile else None
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        if profiler:
            profiler.enable()
        result = run_mission(config, f"{out}/run")
        if profiler:
            profiler.disable()
        wall = time.perf_counter() - t0
    mission = result.metrics.mission
    factor = mission.sim_time_s / wall
    name = f"{args.world} {args.scenario} seed {args.seed}"
    print(f"mission {name}: {result.state} ({result.reason})")
    print(outcome(result.metrics))
    print(
        f"simulated {mission.sim_time_s:.0f} s in {wall:.1f} s wall: {factor:.1f}x real time"
        + target_verdict(factor, TARGET_FACTORS.get((args.world, args.scenario)))
    )
    print(
        f"{mission.frames} camera frames, {mission.lidar_scans} LiDAR scans, "
        f"{mission.local_plans} local plans, {mission.hierarchical_queries} hierarchical "
        f"queries, {mission.distance_m:.0f} m driven"
    )
    categories = mission.wall_time_by_category_s
    other = wall - sum(categories.values())
    print("wall time by category:")
    for name, seconds in sorted(categories.items(), key=lambda item: -item[1]):
        print(f"  {name:<11} {seconds:7.1f} s  {100 * seconds / wall:5.1f} %")
    print(f"  {'other':<11} {other:7.1f} s  {100 * other / wall:5.1f} %  (setup, metrics, files)")
    if profiler:
        pstats.Stats(profiler).sort_stats("cumulative").print_stats(25)


if __name__ == "__main__":
    main()
