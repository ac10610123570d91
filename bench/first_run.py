"""The first mission on a fresh install against a warm one: does compilation leak into timings?

Numba compiles each function the first time it is called and caches the machine code on disk
(``cache=True``). A fresh install has no cache, so without a warm-up the first mission's local
planner pays the compilation inside its timed calls. This script runs the same mission twice,
each in a new process sharing one initially empty numba cache (``NUMBA_CACHE_DIR``): the first
process is a fresh install, the second finds the cache. It prints each run's mean local planning
time and wall time, and the ratio first/warm (1.0 when nothing leaks).

Run: ``.venv/bin/python bench/first_run.py [--world campus] [--scenario small]``
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

MISSION = """
import sys, time
from seminspect.missions.xflie.config import make_config
from seminspect.missions.xflie.run import run_mission
t0 = time.perf_counter()
result = run_mission(make_config({{"world": {world!r}, "scenario": {scenario!r}, "seed": 0}}),
                     sys.argv[1])
print({{"local_ms": result.metrics["mission"]["local_planning_ms_mean"],
        "plans": result.metrics["mission"]["local_plans"],
        "process_s": time.perf_counter() - t0}})
"""


def run_once(code: str, out: Path, cache: Path) -> dict:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    done = subprocess.run(
        [sys.executable, "-c", code, str(out)], env=env, capture_output=True, text=True, check=True
    )
    return json.loads(done.stdout.strip().splitlines()[-1].replace("'", '"'))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--world", default="campus")
    parser.add_argument("--scenario", default="small")
    args = parser.parse_args()
    code = MISSION.format(world=args.world, scenario=args.scenario)
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        first = run_once(code, root / "first", root / "numba-cache")
        warm = run_once(code, root / "warm", root / "numba-cache")
    for name, figures in (("first (empty cache)", first), ("warm (cached)", warm)):
        print(
            f"{name:20s} local planning mean {figures['local_ms']:7.1f} ms over "
            f"{figures['plans']} plans; mission process {figures['process_s']:6.1f} s"
        )
    print(f"first / warm local planning mean: {first['local_ms'] / warm['local_ms']:.2f}")


if __name__ == "__main__":
    main()
