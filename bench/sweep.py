"""Sweep throughput on local Ray: missions per hour with 1 and with 2 workers, and the ratio.

The same grid (small subterranean missions, one seed each) runs twice into fresh directories,
so nothing is reused: once on a local Ray with one worker, once with two. Ray's start is timed
on its own (a fixed cost per sweep); the throughput is the sweep's wall time once Ray is up,
which still includes every worker's first imports and compilation, as a user pays them.

Run: ``.venv/bin/python bench/sweep.py`` (``--missions 8 --budget 400``; ``--json out.json``).
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

from seminspect.missions.xflie.sweep import MISSIONS, SweepSpec, expand
from seminspect.runs.sweep import run_on_ray


def measure(missions: int, budget: float, workers: int) -> dict[str, float]:
    spec = SweepSpec(
        worlds=["subterranean"],
        seeds=list(range(missions)),
        settings={"time_budget_s": [budget]},
    )
    import ray

    with tempfile.TemporaryDirectory(prefix="bench-sweep-") as out:
        tasks = expand(spec, Path(out))
        start = time.perf_counter()
        ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
        ray_start = time.perf_counter() - start
        try:
            start = time.perf_counter()
            rows = run_on_ray(tasks, MISSIONS)  # uses the Ray started above
            wall = time.perf_counter() - start
        finally:
            ray.shutdown()
    failed = sum(row.state == "failed" for row in rows)
    if failed:
        raise SystemExit(f"{failed} of {missions} missions failed; the figure would mean nothing")
    return {
        "workers": workers,
        "missions": missions,
        "ray_start_s": ray_start,
        "wall_s": wall,
        "missions_per_hour": 3600.0 * missions / wall,
        "mean_mission_s": sum(row.wall_s for row in rows) / missions,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--missions", type=int, default=8)
    parser.add_argument("--budget", type=float, default=400.0, help="simulated seconds each")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    one, two = (measure(args.missions, args.budget, workers) for workers in (1, 2))
    ratio = two["missions_per_hour"] / one["missions_per_hour"]
    for figures in (one, two):
        print(
            f"{figures['workers']} worker(s): Ray up in {figures['ray_start_s']:.1f} s, then "
            f"{figures['missions']} missions in {figures['wall_s']:.1f} s = "
            f"{figures['missions_per_hour']:.0f} missions/hour "
            f"(mean {figures['mean_mission_s']:.1f} s per mission inside its task)"
        )
    print(f"scaling 2 workers / 1 worker: {ratio:.2f}x")
    if args.json:
        args.json.write_text(json.dumps({"runs": [one, two], "ratio": ratio}, indent=2) + "\n")


if __name__ == "__main__":
    main()
