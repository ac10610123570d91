"""Regenerate every measured table of docs/reproduction.md and rewrite them in place.

Each table sits between ``<!-- BEGIN table:NAME -->`` and ``<!-- END table:NAME -->`` in the
document; the prose and the paper's own rows around them are left as written. Sections:

* ``table3-city-small``, ``-medium``, ``-large``, ``acceptance``, ``table3-others``: 000 Table 3
  from the missions of ``bench/mission_acceptance.py`` (city small/medium/large x seeds 0-2;
  campus, subterranean, both collapsed buildings);
* ``table5``, ``targets``: 000 Table 5 on the city seed-0 runs of the same missions (queries
  answered by both planners, the volumetric one over the ground band and the full volume);
* ``scaling``: the synthetic-city scaling study (000 Fig 13 analogue);
* ``table6``: 000 Table 6, each city scenario with xFLIE, the volumetric baseline and the
  frontier explorer over seeds 0-2 (``--table6-planner`` runs some of them and keeps the
  document's rows of the others);
* ``rl-table1``, ``rl-table2``, ``rl-table3``: 004 Tables I-III from ``bench/rl_reproduction.py``
  (the shipped policy, its ablations and the baselines, 100 episodes per obstacle count).

Mission runs go under ``--runs`` and are reused when a completed run of the same configuration
is there (``--fresh`` deletes them first, so every figure comes from a new run).

Run: ``.venv/bin/python bench/reproduction.py [--only table3-city-small ...] [--fresh]``
"""

from __future__ import annotations

import argparse
import shutil
import time
from pathlib import Path

from mission_acceptance import CITY, HEADER, OTHERS, acceptance_lines, row, run_acceptance
from planning_targets import targets_markdown, targets_met
from rl_reproduction import SECTIONS as RL_SECTIONS
from rl_reproduction import regenerate as rl_regenerate
from seminspect.report.markdown import rewrite_sections, section_body
from seminspect.studies.planning.scaling import SCALING_SIZES, scaling_study
from seminspect.studies.planning.study import (
    TABLE6_PLANNERS,
    PlanningStudy,
    compare_run,
    mission_study,
)
from seminspect.studies.planning.tables import (
    both_volumes_beside_paper,
    merge_table6_rows,
    scaling_markdown,
    study_document,
    table6_summary,
)

SCENARIOS = ("small", "medium", "large")
CITY_SECTIONS = tuple(f"table3-city-{scenario}" for scenario in SCENARIOS)
SECTIONS = (
    *CITY_SECTIONS,
    "acceptance",
    "table3-others",
    "table5",
    "targets",
    "scaling",
    "table6",
    *RL_SECTIONS,
)
DOC = Path(__file__).resolve().parents[1] / "docs" / "reproduction.md"


def log(text: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')}] {text}", flush=True)


def city_runs(wanted: set[str]) -> list[tuple[str, str | None, int]]:
    """The city missions the wanted sections need: every seed of a scenario whose rows are
    wanted (the acceptance list covers those, or every scenario when it is wanted alone), and
    seed 0 of each for Table 5."""
    scenarios = {s for s in SCENARIOS if f"table3-city-{s}" in wanted}
    if "acceptance" in wanted and not scenarios:
        scenarios = set(SCENARIOS)
    table5 = bool(wanted & {"table5", "targets"})
    return [run for run in CITY if run[1] in scenarios or (table5 and run[2] == 0)]


def table3_sections(runs_dir: Path, wanted: set[str]) -> tuple[dict[str, str], list[Path]]:
    """The Table 3 sections asked for, and the city seed-0 run directories (for Table 5)."""
    results = []
    for metrics in run_acceptance(city_runs(wanted), runs_dir / "acceptance", reuse=True):
        results.append(metrics)
    sections = {"acceptance": "\n".join(acceptance_lines(results))}
    for scenario in SCENARIOS:
        rows = [_row(m) for m in results if m["run"]["scenario"] == scenario]
        sections[f"table3-city-{scenario}"] = "\n".join([HEADER, *rows])
    if "table3-others" in wanted:
        others = run_acceptance(OTHERS, runs_dir / "acceptance", reuse=True)
        sections["table3-others"] = "\n".join([HEADER, *(_row(m) for m in others)])
    seed0 = [runs_dir / "acceptance" / _name(m["run"]) for m in results if m["run"]["seed"] == 0]
    return {k: v for k, v in sections.items() if k in wanted}, seed0


def _row(metrics: dict) -> str:
    run = metrics["run"]
    log(_name(run))
    return row(run["world"], run["scenario"], run["seed"], metrics)


def _name(run: dict) -> str:
    return f"{run['world']}-{run['scenario'] or 'default'}-seed{run['seed']}"


def planning_sections(
    runs_dir: Path,
    seed0_runs: list[Path],
    wanted: set[str],
    *,
    table6_scenarios: list[str],
    table6_planners: list[str],
    doc: Path,
) -> dict[str, str]:
    """Table 5 (both volumes) on the city seed-0 runs, the scaling study and Table 6 (over
    ``table6_scenarios`` and ``table6_planners``; rows of other planners are kept from
    ``doc``)."""
    sections: dict[str, str] = {}
    ground, full = [], []
    if wanted & {"table5", "targets"}:
        for run_dir in seed0_runs:
            log(f"Table 5 queries: {run_dir.name}")
            ground.append(compare_run(run_dir))
            full.append(compare_run(run_dir, volume="full"))
    scaling = []
    if wanted & {"scaling", "targets"}:
        log("scaling study")
        scaling = scaling_study(SCALING_SIZES)
    if "table5" in wanted:
        sections["table5"] = "\n".join(both_volumes_beside_paper(ground, full))
    if "targets" in wanted:
        met = targets_markdown(targets_met(study_document(PlanningStudy(ground, scaling, []))))
        sections["targets"] = met.split("\n", 2)[2]  # without its heading
    if "scaling" in wanted:
        sections["scaling"] = scaling_markdown(scaling).split("\n", 2)[2]
    if "table6" in wanted:
        outcomes = mission_study(
            table6_scenarios, runs_dir / "planning", _table6_log, planners=table6_planners
        )
        current = section_body(doc.read_text(encoding="utf-8"), "table6")
        sections["table6"] = merge_table6_rows(current, table6_summary(outcomes))
    return sections


def _table6_log(label: str, mission: object) -> None:
    if mission is None:
        log(label)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--doc", type=Path, default=DOC, help="the Markdown file to rewrite")
    parser.add_argument(
        "--runs",
        type=Path,
        default=Path("runs/reproduction"),
        help="where the mission runs go; complete runs of the same configuration are reused",
    )
    parser.add_argument(
        "--only", action="append", choices=SECTIONS, help="regenerate this section (repeatable)"
    )
    parser.add_argument(
        "--fresh", action="store_true", help="delete the run directories under --runs first"
    )
    parser.add_argument(
        "--table6-scenario",
        action="append",
        choices=SCENARIOS,
        help="city scenario of Table 6 (repeatable; default: all three)",
    )
    parser.add_argument(
        "--table6-planner",
        action="append",
        choices=TABLE6_PLANNERS,
        help="planner of Table 6 (repeatable; default: all three); the document's rows of the "
        "others are kept",
    )
    args = parser.parse_args()
    wanted = set(args.only or SECTIONS)
    if args.fresh and args.runs.exists():
        shutil.rmtree(args.runs)
    sections, seed0 = table3_sections(args.runs, wanted)
    sections |= planning_sections(
        args.runs,
        seed0,
        wanted,
        table6_scenarios=args.table6_scenario or list(SCENARIOS),
        table6_planners=args.table6_planner or list(TABLE6_PLANNERS),
        doc=args.doc,
    )
    if wanted & set(RL_SECTIONS):
        sections |= rl_regenerate(wanted & set(RL_SECTIONS))
    rewrite_sections(args.doc, sections)
    log(f"rewrote {', '.join(sorted(sections))} in {args.doc}")


if __name__ == "__main__":
    main()
