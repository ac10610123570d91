"""The Table 5 tables of the planning study (000 Table 5 analogue): each query answered by both
planners, the aggregates of a run's queries, and ours beside the paper's per scenario."""

from __future__ import annotations

import dataclasses
import math
import statistics
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from seminspect.studies.xflie.cells import ms_cell, num_cell, pct_cell, ratio_cell, us_cell
from seminspect.studies.xflie.paper import PAPER_TABLE5, PaperQuery
from seminspect.studies.xflie.study import RESOLUTIONS, RunComparison

SCENARIO_NUMBER = {"small": 1, "medium": 2, "large": 3}


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
        vp = " | ".join(f"{ms_cell(r.time_s)} / {num_cell(r.length, 1)}" for r in q.vp)
        check05 = q.vp_check(0.5)
        lines.append(
            f"| {q.query} | {q.straight_m:.1f} | {us_cell(q.hp.target_layer_s)} / "
            f"{q.hp_target_layer_m:.1f} | {us_cell(q.hp.local_layers_s)} | {q.hp_length_m:.1f} "
            f"| {us_cell(q.hp.query_s)} | {q.refined_length_m:.1f} (+{us_cell(q.refine_s)}) | {vp} "
            f"| {ratio_cell(q.time_ratio(0.5))}, {ratio_cell(q.time_ratio(0.5, 'query'))} "
            f"| {num_cell(q.length_ratio(0.5))}, {num_cell(q.length_ratio(0.5, refined=True))} "
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
            f"| {r.vp07_s:.3g} / {r.vp07_m:.2f} | {ratio_cell(r.vp05_s / hp)} "
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

    row("HP Target-layer search (µs)", "hp_target_layer_s", us_cell)
    row("HP Pose/Level-layer searches (µs)", "hp_local_layers_s", us_cell)
    row("HP searches, both layers (µs)", "hp_search_s", us_cell)
    row("HP end to end: parse, localise, search, waypoints (µs)", "hp_query_s", us_cell)
    row("VP at 0.5 m (ms)", "vp_0.5_s", ms_cell)
    row("VP at 0.7 m (ms)", "vp_0.7_s", ms_cell)
    row("VP/HP time at 0.5 m, searches", "time_ratio_0.5_search", ratio_cell)
    row("VP/HP time at 0.5 m, searches (min)", "time_ratio_0.5_search", ratio_cell, "min")
    row("VP/HP time at 0.5 m, end to end", "time_ratio_0.5_query", ratio_cell)
    row("VP/HP time at 0.5 m, end to end (min)", "time_ratio_0.5_query", ratio_cell, "min")
    row("VP/HP time at 0.7 m, searches", "time_ratio_0.7_search", ratio_cell)
    row("HP/VP length at 0.5 m (mean)", "length_ratio_0.5", num_cell, "mean")
    row("HP/VP length at 0.7 m (mean)", "length_ratio_0.7", num_cell, "mean")
    row("refined HP/VP length at 0.5 m (mean)", "refined_length_ratio_0.5", num_cell, "mean")
    row("VP/(HP end to end + refinement) time at 0.5 m", "time_ratio_0.5_refined", ratio_cell)
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
            f"{ratio_cell(summaries[s][key]['median'])} / {ratio_cell(summaries[s][key]['min'])}"
        )

    both, search = (ours, papers), "time_ratio_0.5_search"
    row("HP Target-layer search (µs)", *(cell(x, "hp_target_layer_s", us_cell) for x in both))
    row("HP Pose/Level-layer searches (µs)", *(cell(x, "hp_local_layers_s", us_cell) for x in both))
    row("HP end to end: parse, localise, search, waypoints (µs)", cell(ours, "hp_query_s", us_cell))
    row("VP at 0.5 m, ground band (ms)", *(cell(x, "vp_0.5_s", ms_cell) for x in both))
    if whole:
        row(
            "VP at 0.5 m, full volume (ms)",
            *(cell(x, "vp_0.5_s", ms_cell) for x in (whole, papers)),
        )
    row("VP at 0.7 m, ground band (ms)", *(cell(x, "vp_0.7_s", ms_cell) for x in both))
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
    row(
        "HP/VP length at 0.5 m (mean)",
        *(cell(x, "length_ratio_0.5", num_cell, "mean") for x in both),
    )
    row(
        "refined HP / VP length at 0.5 m (mean)",
        cell(ours, "refined_length_ratio_0.5", num_cell, "mean"),
    )
    checks = ("hp_valid_segments", "refined_valid_segments", "vp_0.5_valid_segments")
    row(
        "valid segments: graph edges, HP, refined, VP 0.5 m",
        lambda s: ", ".join(pct_cell(share) for share in (edges[s], *(ours[s][k] for k in checks))),
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
            f"{pct_cell(dataclasses.asdict(run.edge_check))}, HP paths "
            f"{pct_cell(summary['hp_valid_segments'])}, refined "
            f"{pct_cell(summary['refined_valid_segments'])}, VP 0.5 m "
            f"{pct_cell(summary['vp_0.5_valid_segments'])}.",
            "",
            *query_table(run),
            "",
        ]
        if run.scenario in PAPER_TABLE5:
            lines += [*paper_table(PAPER_TABLE5[run.scenario]), ""]
    lines += ["### Beside the paper", "", *beside_paper(runs), ""]
    return "\n".join(lines)
