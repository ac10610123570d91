"""Every mission behind docs/reproduction.md's mission tables, as one sweep.

The tables report statistics over seeds (``SEEDS``, at least five per row; the golden
envelope's city small missions take ``ENVELOPE_SEEDS``), so their missions are many and
independent: they run as one :mod:`seminspect.missions.xflie.sweep` on a local Ray, a mission per
core, each into its own run directory under the sweep's directory, where a completed run of
the same configuration, code and machine is reused. Table 6's missions charge planning wall
time to the robot's clock; the sweep runs those one at a time (beside the others, never beside
each other), first, because their chain is the longest.

Run on its own (``bench/reproduction.py`` calls it): ``.venv/bin/python
bench/reproduction_missions.py [--runs runs/reproduction/missions] [--section NAME ...]``
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Iterable
from pathlib import Path

from seminspect.missions.xflie.config import CITY_BUDGETS
from seminspect.missions.xflie.sweep import MISSIONS, SweepSpec, expand
from seminspect.runs.sweep import SweepRow, SweepTask, run_on_ray
from seminspect.studies.xflie.missions import TABLE6_PLANNERS

#: Seeds of every mission row of the tables.
SEEDS = tuple(range(5))
#: Seeds of the golden mission's behavioural envelope (city small), also its Table 3 row.
ENVELOPE_SEEDS = tuple(range(60))
CITY_SCENARIOS = ("small", "medium", "large")
#: The team of the two-robot table, and the city it works in.
TEAM = ("explorer", "inspector")
TEAM_SCENARIO = "large"
RUNS = Path("runs/reproduction/missions")


def _table3_specs() -> dict[str, list[SweepSpec]]:
    city = {
        f"table3-city-{scenario}": [
            SweepSpec(
                worlds=["city"],
                scenarios=[scenario],
                seeds=list(ENVELOPE_SEEDS if scenario == "small" else SEEDS),
            )
        ]
        for scenario in CITY_SCENARIOS
    }
    others = [
        SweepSpec(worlds=["campus"], seeds=list(SEEDS)),
        SweepSpec(worlds=["subterranean"], seeds=list(SEEDS)),
        SweepSpec(
            worlds=["collapsed-buildings"],
            scenarios=["fire-station", "industrial"],
            seeds=list(SEEDS),
        ),
    ]
    return {**city, "table3-others": others}


def _table6_specs() -> list[SweepSpec]:
    """000 Table 6: each city scenario under the paper's budget, planning time charged, with
    each planner (largest city first: its missions are the longest)."""
    return [
        SweepSpec(
            worlds=["city"],
            scenarios=[scenario],
            seeds=list(SEEDS),
            settings={
                "planner": list(TABLE6_PLANNERS),
                "charge_planning_time": [True],
                "time_budget_s": [CITY_BUDGETS[scenario]],
            },
        )
        for scenario in reversed(CITY_SCENARIOS)
    ]


def section_specs() -> dict[str, list[SweepSpec]]:
    """The sweep grids of each section whose rows are missions."""
    team = SweepSpec(
        worlds=["city"],
        scenarios=[TEAM_SCENARIO],
        seeds=list(SEEDS),
        settings={"robots": [list(TEAM)]},
    )
    return {**_table3_specs(), "table6": _table6_specs(), "team": [team]}


def section_tasks(section: str, runs: Path = RUNS) -> list[SweepTask]:
    """The missions a section runs itself."""
    return [task for spec in section_specs().get(section, []) for task in expand(spec, runs)]


def mission_tasks(sections: Iterable[str], runs: Path = RUNS) -> list[SweepTask]:
    """The missions ``sections`` read (each once, where sections share one), in sweep order."""
    sections = set(sections)
    if "team" in sections:  # the lone robot of the team table is Table 3's large city
        sections.add(f"table3-city-{TEAM_SCENARIO}")
    tasks: dict[str, SweepTask] = {}
    for section in sorted(sections, key=list(section_specs()).index):
        tasks.update((task.name, task) for task in section_tasks(section, runs))
    return list(tasks.values())


def run_missions(tasks: list[SweepTask]) -> list[SweepRow]:
    """Run (or reuse) every task on a local Ray with one worker per core, logging each end."""
    started = time.perf_counter()

    def done(row: SweepRow) -> None:
        note = "reused" if row.reused else f"{row.wall_s:.0f} s"
        minutes = (time.perf_counter() - started) / 60
        error = f" ({row.error})" if row.error else ""
        print(f"[{minutes:5.1f} min] {row.name}: {row.state}, {note}{error}", flush=True)

    return run_on_ray(tasks, MISSIONS, on_row=done)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=Path, default=RUNS, help="the sweep's directory")
    parser.add_argument(
        "--section",
        action="append",
        choices=sorted(section_specs()),
        help="run this section's missions (repeatable; default: all)",
    )
    args = parser.parse_args()
    tasks = mission_tasks(args.section or section_specs(), args.runs)
    print(f"{len(tasks)} missions under {args.runs}", flush=True)
    rows = run_missions(tasks)
    failed = [row for row in rows if row.state != "completed"]
    print(f"{len(rows) - len(failed)} of {len(rows)} completed", flush=True)


if __name__ == "__main__":
    main()
