"""The planning study's files (000 Table 5, Table 6 and Fig 13 analogues).

:func:`write_study` leaves three files in a directory: ``planning.md`` (the tables of
:mod:`.table5`, the scaling table and :mod:`.table6`, the paper's numbers beside ours),
``scaling.png`` (planning time against the size of the site) and ``planning.json`` (every
figure, versioned; ``bench/planning_targets.py`` judges it against the targets the study was
built to meet).
"""

from __future__ import annotations

import dataclasses
import os
import platform
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from seminspect.core.io import atomic_write_text, finite_or_none, write_versioned_json
from seminspect.report.figures import new_figure, save_figure
from seminspect.studies.xflie.cells import ms_cell, ratio_cell, us_cell
from seminspect.studies.xflie.paper import PAPER_TABLE5, PAPER_TABLE6
from seminspect.studies.xflie.scaling import ScalingPoint
from seminspect.studies.xflie.study import PlanningStudy, QueryComparison
from seminspect.studies.xflie.table5 import paper_summary, run_summary, table5_markdown
from seminspect.studies.xflie.table6 import table6_markdown

STUDY_FORMAT = "seminspect.planning-study"


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
            f"| {us_cell(p.hp_search_s)} ({us_cell(p.hp_search_p95_s)}) "
            f"| {us_cell(p.hp_plan_s)} ({us_cell(p.hp_plan_p95_s)}) | {p.hp_settled:.0f} "
            f"| {ms_cell(p.vp_s)} ({ms_cell(p.vp_p95_s)}) | {ratio_cell(p.ratio_search)} "
            f"| {ratio_cell(p.ratio_plan)} | {p.vp_failures} |"
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
