"""Regenerate every measured table of docs/reproduction.md and rewrite them in place.

Each table sits between ``<!-- BEGIN table:NAME -->`` and ``<!-- END table:NAME -->`` in the
document; the prose and the paper's own rows around them are left as written. Mission tables
are statistics over seeds (``reproduction_missions.SEEDS``): continuous figures as mean ±
standard deviation, counts as median and range, with the seeds and the machine they ran on.
Sections:

* ``table3-city-small``, ``-medium``, ``-large``, ``table3-others``, ``acceptance``: 000
  Table 3 over the city's three scenarios, campus, subterranean and both collapsed buildings;
* ``golden-envelope``: the city small runs' figures as the golden mission's behavioural
  envelope (``tests/missions/xflie/data/golden/city-small-envelope.json``);
* ``table5``, ``targets``: 000 Table 5 on the city seed-0 runs (queries answered by both
  planners, the volumetric one over the ground band and the full volume);
* ``scaling``: the synthetic-city scaling study (000 Fig 13 analogue);
* ``table6``: 000 Table 6, each city scenario with xFLIE, the volumetric baseline and the
  frontier explorer (``--table6-scenario`` / ``--table6-planner`` run some of them and keep the
  document's rows of the others);
* ``team``: two robots against one on the large city;
* ``routine-single``, ``routine-pairs``, ``routine-acceptance``, ``routine-tours``: 002's
  scenarios (``bench/routine_acceptance.py``);
* ``rl-table1``, ``rl-table2``, ``rl-table3``, ``rl-shapes``, ``rl-retrained``: 004 Tables
  I-III, the shapes table and the policies retrained in the paper's rooms from
  ``bench/rl_reproduction.py``
  (the shipped policy, its ablations and the baselines, 100 episodes per obstacle count).

Every mission runs as one ``seminspect`` sweep on a local Ray, one mission per core
(``bench/reproduction_missions.py``), under ``--runs``; completed runs of the same configuration,
code and machine are reused (``--fresh`` deletes them first, so every figure comes from a new
run). The per-run figures of every mission are written to ``docs/data/reproduction/``, the
reference that ``bench/compare_runs.py`` compares other machines and changes with.

Run: ``.venv/bin/python bench/reproduction.py [--only table3-city-small ...] [--fresh]``
"""

from __future__ import annotations

import argparse
import json
import shutil
import time
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

import golden_envelope
import reproduction_missions as missions
from mission_acceptance import PAPER, acceptance_lines
from planning_targets import targets_markdown, targets_met
from rl_reproduction import SECTIONS as RL_SECTIONS
from rl_reproduction import regenerate as rl_regenerate
from seminspect.core.io import atomic_write_text
from seminspect.core.provenance import platform_label
from seminspect.missions.xflie.layout import read_metrics_document
from seminspect.missions.xflie.sweep import MISSIONS
from seminspect.report.markdown import (
    mean_sd,
    median_range,
    rewrite_sections,
    section_body,
    seeds_cell,
)
from seminspect.runs.sweep import SweepRow, SweepTask, sweep_tables
from seminspect.studies.routine import reproduction_sections as routine_sections
from seminspect.studies.routine import run_study as routine_study
from seminspect.studies.routine import tour_study
from seminspect.studies.xflie.missions import TABLE6_PLANNERS, MissionOutcome
from seminspect.studies.xflie.scaling import SCALING_SIZES, scaling_study
from seminspect.studies.xflie.study import PlanningStudy, compare_run
from seminspect.studies.xflie.table5 import both_volumes_beside_paper
from seminspect.studies.xflie.table6 import merge_table6_rows, table6_summary
from seminspect.studies.xflie.tables import scaling_markdown, study_document
from team import TARGET_SPEEDUP_PCT
from team import figures as team_figures

SCENARIOS = missions.CITY_SCENARIOS
CITY_SECTIONS = tuple(f"table3-city-{scenario}" for scenario in SCENARIOS)
ROUTINE_SECTIONS = ("routine-single", "routine-pairs", "routine-acceptance", "routine-tours")
SECTIONS = (
    *CITY_SECTIONS,
    "acceptance",
    "table3-others",
    "golden-envelope",
    "table5",
    "targets",
    "scaling",
    "table6",
    "team",
    *ROUTINE_SECTIONS,
    *RL_SECTIONS,
)
#: Sections that are not tables of docs/reproduction.md.
NOT_IN_DOC = frozenset({"golden-envelope"})
#: The missions each section reads (by the section of reproduction_missions that runs them).
MISSIONS_OF = {
    **{section: [section] for section in CITY_SECTIONS},
    "acceptance": list(CITY_SECTIONS),
    "table3-others": ["table3-others"],
    "golden-envelope": ["table3-city-small"],
    "table5": list(CITY_SECTIONS),
    "targets": list(CITY_SECTIONS),
    "table6": ["table6"],
    "team": ["team"],
}
DOC = Path(__file__).resolve().parents[1] / "docs" / "reproduction.md"
DATA = Path(__file__).resolve().parents[1] / "docs" / "data" / "reproduction"


def log(text: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')}] {text}", flush=True)


# --- runs ----------------------------------------------------------------------------------
class Runs:
    """The finished missions of the sweep: each task's metrics and run directory."""

    def __init__(self, tasks: Sequence[SweepTask], rows: Sequence[SweepRow]) -> None:
        self.tasks = {task.name: task for task in tasks}
        self.rows = list(rows)
        failed = [f"{row.name}: {row.error or row.state}" for row in rows if row.state == "failed"]
        if failed:
            raise SystemExit("missions failed, no table was rewritten:\n" + "\n".join(failed))

    def select(self, section: str) -> list[tuple[SweepTask, dict[str, Any]]]:
        """The tasks of one section of reproduction_missions that ran, with their metrics."""
        names = [t.name for t in missions.section_tasks(section) if t.name in self.tasks]
        return [(self.tasks[n], read_metrics_document(Path(self.tasks[n].run_dir))) for n in names]


def run_all(wanted: set[str], runs_dir: Path, table6_filter: Callable[[SweepTask], bool]) -> Runs:
    sections = sorted({s for section in wanted for s in MISSIONS_OF.get(section, [])})
    tasks = [t for t in missions.mission_tasks(sections, runs_dir) if table6_filter(t)]
    log(f"{len(tasks)} missions on a local Ray, one per core (completed ones reused)")
    rows = missions.run_missions(tasks)
    if tasks:
        publish_rows(rows)
    return Runs(tasks, rows)


def publish_rows(rows: Sequence[SweepRow]) -> None:
    """Write the per-run figures to ``DATA``: these rows in place of the published rows of the
    same missions, the other sections' rows kept, all in the order of the full sweep."""
    published = DATA / "sweep.json"
    kept = {}
    if published.is_file():
        document = json.loads(published.read_text(encoding="utf-8"))
        kept = {row["name"]: SweepRow(**row) for row in document["runs"]}
    kept |= {row.name: row for row in rows}
    order = [task.name for task in missions.mission_tasks(missions.section_specs())]
    DATA.mkdir(parents=True, exist_ok=True)
    sweep_tables([kept[name] for name in order if name in kept], DATA, MISSIONS.columns)


def run_code(task: SweepTask) -> dict[str, Any]:
    """The ``code`` block a run recorded: source hash, git revision, libraries, machine."""
    config = json.loads((Path(task.run_dir) / "config.json").read_text(encoding="utf-8"))
    return config["code"]


def machine_line(group: Iterable[tuple[SweepTask, dict[str, Any]]]) -> str:
    """The kinds of machine that made the runs (``numeric_platform``), with their CPU model."""
    kinds = {}
    for task, _ in group:
        platform = run_code(task)["platform"]
        kinds[platform_label(platform)] = platform.get("cpu_model", "")
    named = [f"{label} ({model})" if model else label for label, model in sorted(kinds.items())]
    return "Machine: " + "; ".join(named) + "."


# --- 000 Table 3 ---------------------------------------------------------------------------
HEADER = (
    "| run | seeds | Target | Level | Pose | Feature | Unified | Reconciled % "
    "| Detected/Inspected % | false targets | RMSE xy (m) | surface coverage % "
    "| box volume (m^3) | collisions | levels by eq 8 / cap | sim s |\n" + "|" + "---|" * 16
)


def _pair(values: list[dict[str, Any]], first: Callable, second: Callable) -> str:
    return f"{median_range(map(first, values))}/{median_range(map(second, values))}"


def table3_row(name: str, runs: list[tuple[SweepTask, dict[str, Any]]]) -> str:
    """One row of 000 Table 3 over a group's seeds."""
    ms = [metrics for _, metrics in runs]
    seeds = [int(task.config["seed"]) for task, _ in runs]
    t3 = [m["table3"] for m in ms]
    layers = [
        _pair(t3, lambda t, k=k: t[k][0], lambda t, k=k: t[k][1])
        for k in ("target", "level", "pose", "feature", "unified")
    ]
    cells = [
        name,
        seeds_cell(seeds),
        *layers,
        mean_sd((t["reconciled_pct"] for t in t3), 1),
        _pair(t3, lambda t: t["detected_pct"], lambda t: t["inspected_pct"]),
        median_range(m["targets"]["false_targets"] for m in ms),
        mean_sd((m["table6"]["localisation_rmse_m"] for m in ms), 3),
        mean_sd((m["table6"]["surface_coverage_pct"] for m in ms), 1),
        mean_sd((m["table6"]["bbox_volume_m3"] for m in ms), 0),
        median_range(m["mission"]["collisions"] for m in ms),
        _pair(
            ms,
            lambda m: m["mission"]["level_endings"]["similarity"],
            lambda m: m["mission"]["level_endings"]["cap"],
        ),
        mean_sd((m["mission"]["sim_time_s"] for m in ms), 0),
    ]
    return "| " + " | ".join(cells) + " |"


def paper_row(scenario: str) -> str:
    """000 Table 3's own row of a city scenario, in the columns of ours."""
    paper = PAPER[scenario]
    layers, unified, reconciled = (part.strip() for part in paper["t3"].split(","))
    cells = [f"paper (000 Table 3, {scenario})", "-", *layers.split(), unified]
    cells += [reconciled.removesuffix(" %"), paper["det"], "-", f"{paper['rmse']}"]
    cells += ["-"] * 5
    return "| " + " | ".join(cells) + " |"


def table3_sections(runs: Runs, wanted: set[str]) -> dict[str, str]:
    sections: dict[str, str] = {}
    for scenario in SCENARIOS:
        name = f"table3-city-{scenario}"
        if name in wanted:
            group = runs.select(name)
            rows = [HEADER, table3_row(f"city {scenario}", group), paper_row(scenario)]
            sections[name] = "\n".join([*rows, "", machine_line(group)])
    if "acceptance" in wanted:
        tagged = []
        for scenario in SCENARIOS:
            for task, metrics in runs.select(f"table3-city-{scenario}"):
                run = {"world": "city", "scenario": scenario, "seed": task.config["seed"]}
                tagged.append({**metrics, "run": run})
        sections["acceptance"] = "\n".join(acceptance_lines(tagged))
    if "table3-others" in wanted:
        group = runs.select("table3-others")
        by_world: dict[str, list[tuple[SweepTask, dict[str, Any]]]] = {}
        for task, metrics in group:
            by_world.setdefault(task.group, []).append((task, metrics))
        rows = [table3_row(name, members) for name, members in by_world.items()]
        sections["table3-others"] = "\n".join([HEADER, *rows, "", machine_line(group)])
    return sections


def write_envelope(runs: Runs) -> None:
    """Record the city small runs as the golden mission's behavioural envelope."""
    group = runs.select("table3-city-small")
    by_seed = {int(task.config["seed"]): metrics for task, metrics in group}
    code = run_code(group[0][0])
    made_on = {key: code[key] for key in ("platform", "dependencies", "source_sha256", "git")}
    golden = {"world": "city", "scenario": "small", "seed": 0}
    document = golden_envelope.envelope_document(golden, made_on, by_seed)
    # Held-out runs on other paths stand while the code that made them is the envelope's.
    if golden_envelope.ENVELOPE.is_file():
        before = golden_envelope.read_envelope()
        if before["made_on"]["source_sha256"] == made_on["source_sha256"]:
            document["held_out"] = before.get("held_out", [])
    atomic_write_text(golden_envelope.ENVELOPE, json.dumps(document, indent=1) + "\n")
    log(f"recorded the envelope of seeds {sorted(by_seed)} in {golden_envelope.ENVELOPE}")


# --- 000 Tables 5 and 6, the team ----------------------------------------------------------
def planning_sections(runs: Runs | None, wanted: set[str], doc: Path) -> dict[str, str]:
    """Table 5 (both volumes) on the city seed-0 runs, the scaling study and Table 6."""
    sections: dict[str, str] = {}
    ground, full = [], []
    if runs is not None and wanted & {"table5", "targets"}:
        for scenario in SCENARIOS:
            task, _ = runs.select(f"table3-city-{scenario}")[0]
            log(f"Table 5 queries: {task.name}")
            ground.append(compare_run(Path(task.run_dir)))
            full.append(compare_run(Path(task.run_dir), volume="full"))
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
    if runs is not None and "table6" in wanted:
        group = runs.select("table6")
        outcomes = [
            MissionOutcome.read(Path(t.run_dir), t.config["scenario"], t.config["planner"])
            for t, _ in group
            if t.name in runs.tasks
        ]
        order = {(s, p): i for i, (s, p) in enumerate(_table6_order())}
        outcomes.sort(key=lambda o: (order[(o.scenario, o.planner)], o.seed))
        current = section_body(doc.read_text(encoding="utf-8"), "table6")
        table = merge_table6_rows(current, table6_summary(outcomes))
        sections["table6"] = table + "\n" + machine_line(group)
    return sections


def _table6_order() -> list[tuple[str, str]]:
    return [(s, p) for s in SCENARIOS for p in TABLE6_PLANNERS]


def team_section(runs: Runs) -> str:
    """Two robots against one on the large city: finish times over the seeds, then each seed."""
    lone = {int(t.config["seed"]): team_figures(Path(t.run_dir)) for t, _ in runs.select(
        f"table3-city-{missions.TEAM_SCENARIO}"
    )}  # fmt: skip
    group = runs.select("team")
    team = {int(t.config["seed"]): team_figures(Path(t.run_dir)) for t, _ in group}
    seeds = sorted(team)
    ratio = {seed: team[seed]["finish_s"] / lone[seed]["finish_s"] for seed in seeds}
    lines = [
        "| seeds | one robot: finish s | last inspection s | team: finish s | last inspection s "
        "| exploration done s | team / one (finish) | found, inspected, false: one / team |",
        "|---|---|---|---|---|---|---|---|",
    ]

    def cell(rows: dict[int, dict[str, Any]], key: str) -> str:
        return mean_sd((rows[seed][key] for seed in seeds), 0)

    outcome = "; ".join(
        f"{lone[s]['found']} {lone[s]['inspected']} {lone[s]['false']} / "
        f"{team[s]['found']} {team[s]['inspected']} {team[s]['false']}"
        for s in seeds
    )
    lines.append(
        f"| {seeds_cell(seeds)} | {cell(lone, 'finish_s')} "
        f"| {cell(lone, 'last_inspection_s')} "
        f"| {cell(team, 'finish_s')} | {cell(team, 'last_inspection_s')} "
        f"| {cell(team, 'exploration_done_s')} | {mean_sd(ratio.values(), 2)} | {outcome} |"
    )
    lines += ["", "Each seed (examples):", ""]
    lines += [
        "| seed | one robot: finish s | team: finish s | team / one | driven one (m) "
        "| driven explorer + inspector (m) | inspected by explorer + inspector |",
        "|---|---|---|---|---|---|---|",
    ]
    lines += [
        f"| {s} | {lone[s]['finish_s']:.0f} | {team[s]['finish_s']:.0f} | {ratio[s]:.2f} "
        f"| {lone[s]['driven']} | {team[s]['driven']} | {team[s]['inspected_by']} |"
        for s in seeds
    ]
    met = sum(100 * (1 - r) >= TARGET_SPEEDUP_PCT for r in ratio.values())
    lines += [
        "",
        f"A team at least {TARGET_SPEEDUP_PCT:.0f} % faster: met in {met} of {len(seeds)} seeds.",
        "",
        machine_line(group),
    ]
    return "\n".join(lines)


# --- the command ---------------------------------------------------------------------------
def regenerate(args: argparse.Namespace) -> dict[str, str]:
    wanted = set(args.only or SECTIONS)

    def table6_filter(task: SweepTask) -> bool:
        if not task.config.get("charge_planning_time"):
            return True
        scenarios = args.table6_scenario or SCENARIOS
        planners = args.table6_planner or TABLE6_PLANNERS
        return task.config["scenario"] in scenarios and task.config["planner"] in planners

    needs_missions = any(MISSIONS_OF.get(section) for section in wanted)
    runs = run_all(wanted, args.runs / "missions", table6_filter) if needs_missions else None
    sections: dict[str, str] = {}
    if runs is not None:
        sections |= table3_sections(runs, wanted)
        if "golden-envelope" in wanted:
            write_envelope(runs)
        if "team" in wanted:
            sections["team"] = team_section(runs)
    sections |= planning_sections(runs, wanted, args.doc)
    if wanted & set(ROUTINE_SECTIONS):
        log("002 routine inspection, every scenario and seed")
        study = routine_study(args.runs / "routine", missions.SEEDS)
        routine = routine_sections(study, tour_study())
        sections |= {name: text for name, text in routine.items() if name in wanted}
    if wanted & set(RL_SECTIONS):
        sections |= rl_regenerate(wanted & set(RL_SECTIONS))
    return {name: text for name, text in sections.items() if name not in NOT_IN_DOC}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--doc", type=Path, default=DOC, help="the Markdown file to rewrite")
    parser.add_argument(
        "--runs",
        type=Path,
        default=Path("runs/reproduction"),
        help="where the runs go; complete runs of the same configuration are reused",
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
    if args.fresh and args.runs.exists():
        shutil.rmtree(args.runs)
    started = time.perf_counter()
    sections = regenerate(args)
    rewrite_sections(args.doc, sections)
    minutes = (time.perf_counter() - started) / 60
    log(f"rewrote {', '.join(sorted(sections))} in {args.doc} ({minutes:.0f} min)")


if __name__ == "__main__":
    main()
