"""Tables, figure and JSON of the planning study (000 Table 5, Table 6 and Fig 13 analogues).

:func:`write_study` leaves three files in a directory: ``planning.md`` (the tables, the paper's
numbers beside ours), ``scaling.png`` (planning time against the size of the site) and
``planning.json`` (every figure, versioned; ``bench/planning_targets.py`` judges it against
the targets the study was built to meet).
"""

from __future__ import annotations

import dataclasses
import math
import os
import platform
import statistics
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from seminspect.core.io import atomic_write_text, finite_or_none, write_versioned_json
from seminspect.missions.xflie.config import inspects
from seminspect.report.figures import new_figure, save_figure
from seminspect.report.markdown import mean_sd
from seminspect.studies.xflie.scaling import ScalingPoint
from seminspect.studies.xflie.study import (
    CITY_SCENARIOS,
    PAPER_TABLE5,
    PAPER_TABLE6,
    RESOLUTIONS,
    TABLE6_PLANNERS,
    MissionOutcome,
    PaperQuery,
    PlanningStudy,
    QueryComparison,
    RunComparison,
)

STUDY_FORMAT = "seminspect.planning-study"
SCENARIO_NUMBER = {"small": 1, "medium": 2, "large": 3}


# ---------------------------------------------------------------------------- aggregates
def stats(values: Iterable[float | None]) -> dict[str, float | int | None]:
    """Median, mean, minimum and maximum of the finite values (``None`` when there are none)."""
    finite = [v for v in values if v is not None and math.isfinite(v)]
    if not finite:
        return {"median": None, "mean": None, "min": None, "max": None, "n": 0}
    return {
        "median": statistics.median(finite),
        "mean": statistics.fmean(finite),
        "min": min(finite),
        "max": max(finite),
        "n": len(finite),
    }


def run_summary(run: RunComparison) -> dict[str, Any]:
    """Medians and ratios of one run's queries (times in seconds)."""
    queries = run.queries
    summary: dict[str, Any] = {
        "hp_target_layer_s": stats(q.hp.target_layer_s for q in queries),
        "hp_local_layers_s": stats(q.hp.local_layers_s for q in queries),
        "hp_search_s": stats(q.hp.search_s for q in queries),
        "hp_plan_s": stats(q.hp.plan_s for q in queries),
        "hp_query_s": stats(q.hp.query_s for q in queries),
        "refine_s": stats(q.refine_s for q in queries),
        "hp_valid_segments": _share(q.hp_check for q in queries),
        "refined_valid_segments": _share(q.refined_check for q in queries),
    }
    for res in RESOLUTIONS:
        key = f"{res:g}"
        summary[f"vp_{key}_s"] = stats(q.volumetric(res).time_s for q in queries)
        summary[f"vp_{key}_valid_segments"] = _share(q.vp_check(res) for q in queries)
        summary[f"vp_{key}_failures"] = sum(q.volumetric(res).error is not None for q in queries)
        for basis in ("search", "plan", "query", "refined"):
            summary[f"time_ratio_{key}_{basis}"] = stats(q.time_ratio(res, basis) for q in queries)
        summary[f"length_ratio_{key}"] = stats(q.length_ratio(res) for q in queries)
        summary[f"refined_length_ratio_{key}"] = stats(
            q.length_ratio(res, refined=True) for q in queries
        )
    return summary


def _share(checks: Iterable[Any]) -> dict[str, int]:
    checks = list(checks)
    return {"valid": sum(c.valid for c in checks), "segments": sum(c.segments for c in checks)}


def paper_summary(rows: Sequence[PaperQuery]) -> dict[str, Any]:
    """The same aggregates over the paper's rows of Table 5 (HP time = Target + Pose layers)."""
    return {
        "hp_target_layer_s": stats(r.target_layer_s for r in rows),
        "hp_local_layers_s": stats(r.pose_layer_s for r in rows),
        "hp_search_s": stats(r.target_layer_s + r.pose_layer_s for r in rows),
        "vp_0.5_s": stats(r.vp05_s for r in rows),
        "vp_0.7_s": stats(r.vp07_s for r in rows),
        "time_ratio_0.5_search": stats(
            r.vp05_s / (r.target_layer_s + r.pose_layer_s) for r in rows
        ),
        "time_ratio_0.7_search": stats(
            r.vp07_s / (r.target_layer_s + r.pose_layer_s) for r in rows
        ),
        "length_ratio_0.5": stats(r.pose_layer_m / r.vp05_m for r in rows),
        "length_ratio_0.7": stats(r.pose_layer_m / r.vp07_m for r in rows),
    }


# ---------------------------------------------------------------------------- markdown
def _us(seconds: float | None) -> str:
    return "-" if seconds is None or not math.isfinite(seconds) else f"{seconds * 1e6:.1f}"


def _ms(seconds: float | None) -> str:
    return "-" if seconds is None or not math.isfinite(seconds) else f"{seconds * 1e3:.2f}"


def _num(value: float | None, digits: int = 2) -> str:
    return "-" if value is None or not math.isfinite(value) else f"{value:.{digits}f}"


def _ratio(value: float | None) -> str:
    if value is None or not math.isfinite(value):
        return "-"
    return f"{value:,.0f}" if value >= 10 else f"{value:.1f}"


def _pct(share: dict[str, int]) -> str:
    if not share["segments"]:
        return "-"
    return f"{100 * share['valid'] / share['segments']:.1f}% of {share['segments']}"


def query_table(run: RunComparison) -> list[str]:
    """One row per query: both planners side by side (times in µs and ms, lengths in m)."""
    vp_cols = " | ".join(f"VP {r:g} m: ms / m" for r in RESOLUTIONS)
    lines = [
        f"| Query | straight m | HP Target layer: µs / m | HP Pose+Level layers µs | HP path m "
        f"| HP end-to-end µs | refined m (+µs) | {vp_cols} | VP/HP time at 0.5 (search, "
        "end-to-end) | HP/VP length at 0.5 (raw, refined) | valid segments HP, refined, VP 0.5 |",
        "|" + "---|" * (10 + len(RESOLUTIONS)),
    ]
    for q in run.queries:
        vp = " | ".join(f"{_ms(r.time_s)} / {_num(r.length, 1)}" for r in q.vp)
        check05 = q.vp_check(0.5)
        lines.append(
            f"| {q.query} | {q.straight_m:.1f} | {_us(q.hp.target_layer_s)} / "
            f"{q.hp_target_layer_m:.1f} | {_us(q.hp.local_layers_s)} | {q.hp_length_m:.1f} "
            f"| {_us(q.hp.query_s)} | {q.refined_length_m:.1f} (+{_us(q.refine_s)}) | {vp} "
            f"| {_ratio(q.time_ratio(0.5))}, {_ratio(q.time_ratio(0.5, 'query'))} "
            f"| {_num(q.length_ratio(0.5))}, {_num(q.length_ratio(0.5, refined=True))} "
            f"| {q.hp_check.valid}/{q.hp_check.segments}, "
            f"{q.refined_check.valid}/{q.refined_check.segments}, "
            f"{check05.valid}/{check05.segments} |"
        )
    return lines


def paper_table(rows: Sequence[PaperQuery]) -> list[str]:
    lines = [
        "| Query (000 Table 5) | Target layer: s / m | Pose layer: s / m | VP 0.5 m: s / m "
        "| VP 0.7 m: s / m | VP/HP time at 0.5 | HP/VP length at 0.5 |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        hp = r.target_layer_s + r.pose_layer_s
        lines.append(
            f"| {r.query} | {r.target_layer_s:.2g} / {r.target_layer_m:.2f} "
            f"| {r.pose_layer_s:.2g} / {r.pose_layer_m:.2f} | {r.vp05_s:.3g} / {r.vp05_m:.2f} "
            f"| {r.vp07_s:.3g} / {r.vp07_m:.2f} | {_ratio(r.vp05_s / hp)} "
            f"| {r.pose_layer_m / r.vp05_m:.2f} |"
        )
    return lines


def beside_paper(runs: Sequence[RunComparison]) -> list[str]:
    """Per scenario, our aggregate beside the paper's for the same measure."""
    ours = {run.scenario: run_summary(run) for run in runs}
    papers = {s: paper_summary(PAPER_TABLE5[s]) for s in ours if s in PAPER_TABLE5}
    columns = [s for s in ours if s in papers]
    header = " | ".join(
        f"S{SCENARIO_NUMBER[s]} ours | S{SCENARIO_NUMBER[s]} paper" for s in columns
    )
    lines = [
        f"| Measure (median unless stated) | {header} |",
        "|---" * (1 + 2 * len(columns)) + "|",
    ]

    def row(name: str, key: str, fmt, stat: str = "median") -> None:
        cells = []
        for s in columns:
            cells.append(fmt(ours[s][key][stat]))
            cells.append(fmt(papers[s][key][stat]) if key in papers[s] else "-")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")

    row("HP Target-layer search (µs)", "hp_target_layer_s", _us)
    row("HP Pose/Level-layer searches (µs)", "hp_local_layers_s", _us)
    row("HP searches, both layers (µs)", "hp_search_s", _us)
    row("HP end to end: parse, localise, search, waypoints (µs)", "hp_query_s", _us)
    row("VP at 0.5 m (ms)", "vp_0.5_s", _ms)
    row("VP at 0.7 m (ms)", "vp_0.7_s", _ms)
    row("VP/HP time at 0.5 m, searches", "time_ratio_0.5_search", _ratio)
    row("VP/HP time at 0.5 m, searches (min)", "time_ratio_0.5_search", _ratio, "min")
    row("VP/HP time at 0.5 m, end to end", "time_ratio_0.5_query", _ratio)
    row("VP/HP time at 0.5 m, end to end (min)", "time_ratio_0.5_query", _ratio, "min")
    row("VP/HP time at 0.7 m, searches", "time_ratio_0.7_search", _ratio)
    row("HP/VP length at 0.5 m (mean)", "length_ratio_0.5", _num, "mean")
    row("HP/VP length at 0.7 m (mean)", "length_ratio_0.7", _num, "mean")
    row("refined HP/VP length at 0.5 m (mean)", "refined_length_ratio_0.5", _num, "mean")
    row("VP/(HP end to end + refinement) time at 0.5 m", "time_ratio_0.5_refined", _ratio)
    return lines


def both_volumes_beside_paper(
    ground: Sequence[RunComparison], full: Sequence[RunComparison]
) -> list[str]:
    """The condensed Table 5 of docs/reproduction.md: per scenario, our medians over the ground
    band and the full volume (the same queries) beside the paper's."""
    ours = {run.scenario: run_summary(run) for run in ground}
    whole = {run.scenario: run_summary(run) for run in full}
    edges = {run.scenario: dataclasses.asdict(run.edge_check) for run in ground}
    columns = [s for s in ours if s in PAPER_TABLE5]
    papers = {s: paper_summary(PAPER_TABLE5[s]) for s in columns}
    header = " | ".join(
        f"S{SCENARIO_NUMBER[s]} ours | S{SCENARIO_NUMBER[s]} paper" for s in columns
    )
    lines = [
        f"| Measure (median unless stated) | {header} |",
        "|---" * (1 + 2 * len(columns)) + "|",
    ]

    def row(name: str, our_cell, paper_cell=None) -> None:
        cells = []
        for s in columns:
            cells += [our_cell(s), paper_cell(s) if paper_cell else "-"]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")

    def cell(summaries: dict[Any, Any], key: str, fmt, stat: str = "median"):
        return lambda s: fmt(summaries[s][key][stat])

    def median_min(summaries: dict[Any, Any], key: str):
        return lambda s: (
            f"{_ratio(summaries[s][key]['median'])} / {_ratio(summaries[s][key]['min'])}"
        )

    both, search = (ours, papers), "time_ratio_0.5_search"
    row("HP Target-layer search (µs)", *(cell(x, "hp_target_layer_s", _us) for x in both))
    row("HP Pose/Level-layer searches (µs)", *(cell(x, "hp_local_layers_s", _us) for x in both))
    row("HP end to end: parse, localise, search, waypoints (µs)", cell(ours, "hp_query_s", _us))
    row("VP at 0.5 m, ground band (ms)", *(cell(x, "vp_0.5_s", _ms) for x in both))
    if whole:
        row("VP at 0.5 m, full volume (ms)", *(cell(x, "vp_0.5_s", _ms) for x in (whole, papers)))
    row("VP at 0.7 m, ground band (ms)", *(cell(x, "vp_0.7_s", _ms) for x in both))
    row(
        "VP/HP time at 0.5 m, searches, ground (median / min)",
        *(median_min(x, search) for x in both),
    )
    if whole:
        row("VP/HP time at 0.5 m, searches, full (median / min)", median_min(whole, search))
    row(
        "VP/HP time at 0.5 m, end to end, ground (median / min)",
        median_min(ours, "time_ratio_0.5_query"),
    )
    row("HP/VP length at 0.5 m (mean)", *(cell(x, "length_ratio_0.5", _num, "mean") for x in both))
    row(
        "refined HP / VP length at 0.5 m (mean)",
        cell(ours, "refined_length_ratio_0.5", _num, "mean"),
    )
    checks = ("hp_valid_segments", "refined_valid_segments", "vp_0.5_valid_segments")
    row(
        "valid segments: graph edges, HP, refined, VP 0.5 m",
        lambda s: ", ".join(_pct(share) for share in (edges[s], *(ours[s][k] for k in checks))),
    )
    return lines


def table5_markdown(runs: Sequence[RunComparison]) -> str:
    lines = ["## Hierarchical versus volumetric planning (000 Table 5 analogue)", ""]
    for run in runs:
        number = SCENARIO_NUMBER.get(run.scenario or "", "?")
        summary = run_summary(run)
        lines += [
            f"### City {run.scenario} (scenario {number})",
            "",
            f"Run `{run.run_dir}`: {run.inspected_targets} inspected targets, "
            f"times are medians of {run.repeats} calls (HP, refinement) and {run.vp_repeats} (VP), "
            f"{run.graph_nodes} graph nodes; start (robot's final pose) "
            f"{np.round(run.start, 2).tolist()}. Volumetric maps built once in "
            + ", ".join(f"{1e3 * s:.0f} ms ({r:g} m)" for r, s in run.map_build_s.items())
            + ". Valid segments (true world, robot radius): graph edges "
            f"{_pct(dataclasses.asdict(run.edge_check))}, HP paths "
            f"{_pct(summary['hp_valid_segments'])}, refined "
            f"{_pct(summary['refined_valid_segments'])}, VP 0.5 m "
            f"{_pct(summary['vp_0.5_valid_segments'])}.",
            "",
            *query_table(run),
            "",
        ]
        if run.scenario in PAPER_TABLE5:
            lines += [*paper_table(PAPER_TABLE5[run.scenario]), ""]
    lines += ["### Beside the paper", "", *beside_paper(runs), ""]
    return "\n".join(lines)


def common_target_rmse(outcomes: Sequence[MissionOutcome], planner: str) -> float | None:
    """Horizontal RMSE of ``planner``'s missions over the targets that it and its counterpart
    (:func:`_other_planner`) both scored in the same scenario and seed, pooled over the runs:
    two planners on one target set (each mission's own RMSE covers whatever it scored within
    its budget)."""
    runs = {(o.scenario, o.seed, o.planner): o for o in outcomes}
    errors = []
    for (scenario, seed, name), outcome in runs.items():
        other = runs.get((scenario, seed, _other_planner(name)))
        if name != planner or other is None:
            continue
        shared = outcome.inspected_errors.keys() & other.inspected_errors.keys()
        errors += [outcome.inspected_errors[truth] for truth in shared]
    return math.sqrt(statistics.fmean(e * e for e in errors)) if errors else None


def _other_planner(planner: str) -> str:
    """xFLIE is compared with the volumetric baseline; each baseline (the frontier explorer
    too) with xFLIE."""
    return "volumetric" if planner == "hierarchical" else "hierarchical"


def table6_summary(outcomes: Sequence[MissionOutcome]) -> str:
    """One row per scenario and planner over the seeds: mean ± standard deviation, the paper's
    figure in brackets where 000 Table 6 gives one."""
    lines = [
        "| Scenario | Planner | seeds | planning load % | CPU load % (paper) "
        "| coverage m³ (paper) | RMSE m, own targets (paper) | RMSE m, common targets "
        "| inspected / true | sim s |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    groups: dict[tuple[str, str], list[MissionOutcome]] = {}
    for o in outcomes:
        groups.setdefault((o.scenario, o.planner), []).append(o)
    for (scenario, planner), runs in groups.items():
        cpu, cover, rmse = PAPER_TABLE6.get(scenario, {}).get(planner, (None, None, None))
        common = common_target_rmse([o for o in outcomes if o.scenario == scenario], planner)
        inspected = "; ".join(f"{_scored_count(o)} / {o.true_targets}" for o in runs)
        lines.append(
            f"| {scenario} | {planner} | {', '.join(str(o.seed) for o in runs)} "
            f"| {mean_sd((o.planning_load_pct for o in runs), 3)} "
            f"| {mean_sd((o.cpu_load_pct for o in runs), 1)} ({_num(cpu, 1)}) "
            f"| {mean_sd((o.bbox_volume_m3 for o in runs), 1)} ({_num(cover, 1)}) "
            f"| {mean_sd((o.rmse_m for o in runs), 3)} ({_num(rmse, 3)}) "
            f"| {_num(common, 3)} | {inspected} | {mean_sd((o.sim_time_s for o in runs), 0)} |"
        )
    return "\n".join(lines) + "\n"


def merge_table6_rows(current: str, fresh: str) -> str:
    """``fresh`` (a :func:`table6_summary`) with the rows of ``current`` (an earlier one) for
    scenarios and planners it lacks: regenerating one planner's missions keeps the others' rows.
    Rows are ordered by scenario, then planner as in ``TABLE6_PLANNERS``."""
    header, rows = _table_rows(fresh)
    _, kept = _table_rows(current)
    by_key = {_row_key(row): row for row in kept} | {_row_key(row): row for row in rows}

    def order(key: tuple[str, str]) -> tuple[int, int, str, str]:
        scenario, planner = key
        return (_index(CITY_SCENARIOS, scenario), _index(TABLE6_PLANNERS, planner), *key)

    return "\n".join([*header, *(by_key[key] for key in sorted(by_key, key=order))]) + "\n"


def _table_rows(table: str) -> tuple[list[str], list[str]]:
    """A Markdown table's header lines (title and rule) and its rows."""
    lines = [line for line in table.splitlines() if line.startswith("|")]
    return lines[:2], lines[2:]


def _row_key(row: str) -> tuple[str, str]:
    """The scenario and planner cells of a Table 6 row."""
    cells = [cell.strip() for cell in row.strip("|").split("|")]
    return cells[0], cells[1]


def _index(names: Sequence[str], name: str) -> int:
    return names.index(name) if name in names else len(names)


def _scored_count(outcome: MissionOutcome) -> str:
    """Targets inspected, or for a mission that never inspects those found ("found 4")."""
    return str(outcome.inspected) if inspects(outcome.planner) else f"found {outcome.found}"


def table6_markdown(outcomes: Sequence[MissionOutcome]) -> str:
    lines = [
        "## Mission-level effect (000 Table 6 analogue; planning time charged to the robot)",
        "",
        table6_summary(outcomes),
        "Each run:",
        "",
        "| Scenario | seed | Planner | CPU load % (paper) | planning load % "
        "| coverage m³ (paper) | surface coverage % | RMSE m (paper) | inspected / true | sim s "
        "| planning wall s | route plans |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for o in outcomes:
        paper = PAPER_TABLE6.get(o.scenario, {}).get(o.planner)
        cpu, cover, rmse = paper if paper else (None, None, None)
        lines.append(
            f"| {o.scenario} | {o.seed} | {o.planner} | {_num(o.cpu_load_pct, 1)} ({_num(cpu, 1)}) "
            f"| {_num(o.planning_load_pct, 3)} | {_num(o.bbox_volume_m3, 1)} ({_num(cover, 1)}) "
            f"| {_num(o.surface_coverage_pct, 1)} | {_num(o.rmse_m, 3)} ({_num(rmse, 3)}) "
            f"| {_scored_count(o)} / {o.true_targets} | {o.sim_time_s:.0f} "
            f"| {o.planning_wall_s:.2f} | {o.route_plans} |"
        )
    return "\n".join(lines) + "\n"


def scaling_markdown(points: Sequence[ScalingPoint]) -> str:
    lines = [
        "## Scaling (000 Fig 13 analogue and beyond)",
        "",
        "| vehicles | graph nodes | map cells (0.5 m, ground band) | HP searches µs (p95) "
        "| HP plan µs (p95) | nodes settled | VP ms (p95) | VP/HP searches | VP/HP plan "
        "| VP failures |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for p in points:
        lines.append(
            f"| {p.targets:,} | {p.graph_nodes:,} | {p.map_cells:,} "
            f"| {_us(p.hp_search_s)} ({_us(p.hp_search_p95_s)}) "
            f"| {_us(p.hp_plan_s)} ({_us(p.hp_plan_p95_s)}) | {p.hp_settled:.0f} "
            f"| {_ms(p.vp_s)} ({_ms(p.vp_p95_s)}) | {_ratio(p.ratio_search)} "
            f"| {_ratio(p.ratio_plan)} | {p.vp_failures} |"
        )
    return "\n".join(lines) + "\n"


def _volume_phrase(study: PlanningStudy) -> str:
    volumes = {run.volume for run in study.table5} or {"ground"}
    phrases = {
        "ground": "the robot's height band, 8-connected",
        "full": "the map's whole height, 26-connected, as the paper's aerial D*+",
    }
    return "; ".join(phrases[v] for v in sorted(volumes))


def study_markdown(study: PlanningStudy) -> str:
    parts = ["# Planning study: hierarchical (3DLSG) versus volumetric planning", ""]
    parts.append(
        f"Measured on this machine ({machine_line()}). HP = hierarchical planner, VP = "
        f"volumetric baseline (A* over {_volume_phrase(study)}, robot radius 0.4 m, risk band "
        "0.2 m); paper numbers are 000's.\n"
    )
    if study.table5:
        parts.append(table5_markdown(study.table5))
    if study.scaling:
        parts.append(scaling_markdown(study.scaling))
    if study.table6:
        parts.append(table6_markdown(study.table6))
    return "\n".join(parts)


# ---------------------------------------------------------------------------- figure
def scaling_figure(points: Sequence[ScalingPoint]) -> Figure:
    """Planning time against the size of the site, both planners (log-log)."""
    figure = new_figure(15, 4.6)
    axes = figure.subplots(1, 3)
    targets = np.array([p.targets for p in points], dtype=float)
    nodes = np.array([p.graph_nodes for p in points], dtype=float)
    volume = np.array([p.map_volume_m3 for p in points], dtype=float)
    search = np.array([p.hp_search_s for p in points]) * 1e6
    plan = np.array([p.hp_plan_s for p in points]) * 1e6
    vp = np.array([p.vp_s for p in points]) * 1e6
    left, middle, right = axes
    left.plot(targets, plan, "o-", color="tab:green", label="HP plan (localise, search, path)")
    left.plot(targets, search, "s-", color="tab:olive", label="HP searches")
    left.plot(targets, vp, "^-", color="tab:red", label="VP A* at 0.5 m")
    left.plot(targets, search[0] * targets / targets[0], ":", color="grey", label="linear growth")
    left.set(xlabel="vehicles (inspected targets)", ylabel="median planning time (µs)")
    left.set_title("Planning time against site size")
    middle.errorbar(
        nodes, plan, yerr=[0 * plan, np.array([p.hp_plan_p95_s for p in points]) * 1e6 - plan],
        fmt="o-", color="tab:green", capsize=3, label="HP plan (median, p95)",
    )  # fmt: skip
    middle.set(xlabel="3DLSG nodes (unified graph)", ylabel="planning time (µs)")
    middle.set_title("Hierarchical: time against graph size")
    right.errorbar(
        volume, vp, yerr=[0 * vp, np.array([p.vp_p95_s for p in points]) * 1e6 - vp],
        fmt="^-", color="tab:red", capsize=3, label="VP (median, p95)",
    )  # fmt: skip
    right.set(xlabel="voxel map volume (m³)", ylabel="planning time (µs)")
    right.set_title("Volumetric: time against map volume")
    for ax in axes:
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    figure.tight_layout()
    return figure


# ---------------------------------------------------------------------------- JSON and files
def machine_line() -> str:
    info = machine_info()
    return f"{info['cpus']} CPU cores, Python {info['python']}, numpy {info['numpy']}"


def machine_info() -> dict[str, Any]:
    return {
        "cpus": os.cpu_count(),
        "processor": platform.processor() or platform.machine(),
        "python": platform.python_version(),
        "numpy": np.__version__,
    }


def study_document(study: PlanningStudy) -> dict[str, Any]:
    """Every figure of the study as plain JSON values."""
    return {
        "machine": machine_info(),
        "table5": [
            {
                "scenario": run.scenario,
                "run_dir": str(run.run_dir),
                "volume": run.volume,
                "repeats": {"hierarchical": run.repeats, "volumetric": run.vp_repeats},
                "graph_edge_check": dataclasses.asdict(run.edge_check),
                "start": run.start.tolist(),
                "graph_nodes": run.graph_nodes,
                "inspected_targets": run.inspected_targets,
                "map_build_s": {f"{r:g}": s for r, s in run.map_build_s.items()},
                "summary": run_summary(run),
                "paper": paper_summary(PAPER_TABLE5[run.scenario])
                if run.scenario in PAPER_TABLE5
                else None,
                "queries": [_query_document(q) for q in run.queries],
            }
            for run in study.table5
        ],
        "paper_table5": {
            s: [dataclasses.asdict(r) for r in rows] for s, rows in PAPER_TABLE5.items()
        },
        "scaling": [dataclasses.asdict(p) for p in study.scaling],
        "table6": [{**dataclasses.asdict(o), "run_dir": str(o.run_dir)} for o in study.table6],
        "paper_table6": PAPER_TABLE6,
    }


def _query_document(q: QueryComparison) -> dict[str, Any]:
    return {
        "query": q.query,
        "goal": q.goal,
        "straight_m": q.straight_m,
        "hp": dataclasses.asdict(q.hp),
        "hp_target_layer_m": q.hp_target_layer_m,
        "hp_length_m": q.hp_length_m,
        "hp_check": dataclasses.asdict(q.hp_check),
        "refined_length_m": q.refined_length_m,
        "refine_s": q.refine_s,
        "refined_check": dataclasses.asdict(q.refined_check),
        "vp": [
            {
                "resolution": r.resolution,
                "time_s": r.time_s,
                "length_m": r.length,
                "expansions": r.expansions,
                "goal_radius": r.goal_radius,
                "error": r.error,
                "check": dataclasses.asdict(c),
                "time_ratio_search": q.time_ratio(r.resolution),
                "time_ratio_end_to_end": q.time_ratio(r.resolution, "query"),
                "length_ratio": q.length_ratio(r.resolution),
                "refined_length_ratio": q.length_ratio(r.resolution, refined=True),
            }
            for r, c in zip(q.vp, q.vp_checks, strict=True)
        ],
    }


def _json_safe(value: Any) -> Any:
    """The document with NaN and infinities (failed or empty measurements) as ``null``."""
    if isinstance(value, dict):
        return {key: _json_safe(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_json_safe(item) for item in value]
    if isinstance(value, float):
        return finite_or_none(value)
    return value


def write_study(study: PlanningStudy, out_dir: str | os.PathLike[str]) -> dict[str, Path]:
    """``planning.md``, ``planning.json`` and (with scaling points) ``scaling.png``."""
    root = Path(out_dir)
    written = {
        "markdown": atomic_write_text(root / "planning.md", study_markdown(study)),
        "json": write_versioned_json(
            root / "planning.json", STUDY_FORMAT, 1, _json_safe(study_document(study)), indent=2
        ),
    }
    if study.scaling:
        written["figure"] = save_figure(scaling_figure(study.scaling), root / "scaling.png")
    return written
