"""Reproduce 002's routine-inspection results in simulation and check issue 11's figures.

Runs every scenario of ``seminspect.studies.routine`` over the seeds (nominal and obstructed
adaptive; receding and advancing adaptive and non-adaptive on one M_H), then times SA-TSP against
LKH (elkai) on view grids of growing size. Prints the Markdown tables (mean ± standard deviation
over the seeds, counts as median and range) and the acceptance checks (how many seeds meet
each), and writes every figure to a JSON file. Simulated figures do not depend on the machine's
speed; the timings do. ``bench/reproduction.py --only routine`` writes the same tables into
docs/reproduction.md.

Run: ``.venv/bin/python bench/routine_acceptance.py [--out runs/routine-acceptance]
[--json routine-acceptance.json] [--seeds 0 1 2 3 4]``
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

import numpy as np

from seminspect.studies.routine.checks import acceptance_checks, acceptance_lines, task_gaps
from seminspect.studies.routine.study import SEEDS, run_study, tour_study
from seminspect.studies.routine.tables import pair_table, single_table, tours_table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path("runs/routine-acceptance"))
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--seeds", type=int, nargs="+", default=list(SEEDS))
    args = parser.parse_args()
    study = run_study(args.out, tuple(args.seeds))
    tours = tour_study()
    print("## nominal and obstructed (002 Fig 8; paper: Γ_s below 0.5 throughout, utility 0.71)")
    print(single_table(study))
    print("\n## receding and advancing: adaptive / non-adaptive")
    print(pair_table(study))
    print("\n## SA-TSP against LKH (elkai)")
    print(tours_table(tours))
    print("\n## acceptance")
    print("\n".join(acceptance_lines(acceptance_checks(study))))
    print(f"- SA-TSP: largest gap to LKH on a task {max(task_gaps(study)):.2f} %")
    if args.json:
        document = {**study.to_json(), "tours": [dataclasses.asdict(t) for t in tours]}
        args.json.write_text(json.dumps(document, indent=1, default=float))


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
