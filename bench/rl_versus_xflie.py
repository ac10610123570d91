"""The shipped learned policy (004) beside xFLIE's aerial inspection (000) in the same rooms.

Both fly the same 004 protocol rooms (10 x 10 x 4 m, 9 obstacles, the shipped policy's own
observations) from the same start, and both are scored by the 004 camera and its strict
coverage rule against the same feasible faces; xFLIE's trajectory is replayed through that
camera at 10 Hz (``seminspect.studies.learning.versus_xflie``). Prints the table (strict
coverage at 90 s and at the horizon, times to 50 % and 80 % of the feasible, crashes), xFLIE's
stop reasons and the wall time; ``--figure PATH`` draws coverage against time.

Run: ``.venv/bin/python bench/rl_versus_xflie.py [--rooms N] [--quick] [--figure PATH]``
(the default, 8 rooms over 150 s, takes about 6 minutes on 2 cores; ``--quick``: 2 rooms,
100 s).
"""

from __future__ import annotations

import argparse
import time
from collections import Counter
from pathlib import Path

from seminspect.missions.learning.agent import load_controller
from seminspect.missions.learning.env_config import TARGET_SHAPES
from seminspect.missions.learning.evaluation import controller_evaluation_config
from seminspect.report.figures import save_figure
from seminspect.studies.learning.versus_xflie import run_versus, versus_figure, versus_markdown


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--rooms", type=int, default=8, help="rooms (default 8)")
    parser.add_argument("--seconds", type=int, default=150, help="horizon of both (default 150)")
    parser.add_argument("--obstacles", type=int, default=9, help="per room (default 9)")
    parser.add_argument("--shapes", nargs="+", default=["cylinder"], choices=TARGET_SHAPES)
    parser.add_argument("--noise", choices=("realistic", "ideal"), default="realistic")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--quick", action="store_true", help="2 rooms, 100 s")
    parser.add_argument("--figure", type=Path, help="write coverage against time here")
    args = parser.parse_args()
    rooms, seconds = (2, 100) if args.quick else (args.rooms, args.seconds)
    controller = load_controller()
    config = controller_evaluation_config(controller, args.shapes).model_copy(
        update={"obstacles": args.obstacles}
    )
    started = time.perf_counter()
    result = run_versus(
        controller, config, rooms, seed=args.seed, seconds=seconds, noise=args.noise
    )
    print(versus_markdown(result))
    print(f"\nxFLIE stopped: {dict(Counter(result.stop_reasons))}")
    print(f"feasible faces per room: {result.feasible}; rooms skipped: {result.skipped}")
    parts = ", ".join(f"{name} {wall:.0f} s" for name, wall in result.wall_s.items())
    print(f"wall time: {time.perf_counter() - started:.0f} s ({parts})")
    if args.figure is not None:
        print(f"figure: {save_figure(versus_figure(result), args.figure)}")


if __name__ == "__main__":
    main()
