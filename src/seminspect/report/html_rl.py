"""``report.html`` of an ``rl eval`` directory (004): coverage over time, outcomes, episodes.

Drawn from ``evaluation.json`` alone (and the PNGs beside it): the mean strict coverage (of the
feasible faces) against time per obstacle count with its 5th-95th percentile band (004 Fig 5),
every episode's final strict coverage, the table beside 004 Table I (lenient and strict
coverage, crash % with its 95 % interval), one row per episode, and the evaluation's pictures.
"""

from __future__ import annotations

import os
from pathlib import Path

import plotly.graph_objects as go

from seminspect.missions.learning.evaluation import (
    PAPER_TABLE1,
    EvaluationResult,
    ObstacleResult,
    interval_text,
)
from seminspect.report.html_page import (
    REPORT_FILE,
    Section,
    key_value_table,
    pictures_section,
    rows_table,
    write_page,
)

EVALUATION_FILE = "evaluation.json"
#: Episode pictures ``rl eval`` draws per obstacle count, after ``coverage.png``.
_EPISODE_PICTURES = ("top", "3d", "coverage")
_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2")


def write_rl_report(run_dir: str | os.PathLike[str]) -> Path:
    """``report.html`` of a directory holding ``evaluation.json``; returns its path."""
    root = Path(run_dir)
    result = EvaluationResult.from_json(root / EVALUATION_FILE)
    figures = [("coverage", coverage_plot(result)), ("outcomes", outcome_plot(result))]
    sections = [
        Section("Evaluation", key_value_table(_facts(result))),
        Section("Outcomes beside 004 Table I", _table1(result)),
    ]
    trailing = [Section("Episodes", _episodes_table(result))]
    names = ["coverage.png"] + [
        f"episode_{row.obstacles:02d}_{kind}.png"
        for row in result.results
        for kind in _EPISODE_PICTURES
    ]
    if (pictures := pictures_section(root, names)) is not None:
        trailing.append(pictures)
    trailing.append(Section("Environment", key_value_table(result.config.model_dump())))
    title = f"Learned inspection: {result.policy} evaluated in {root.name}"
    return write_page(
        root / REPORT_FILE, title, figures, sections, {}, hover_hint=None, trailing=trailing
    )


def _facts(result: EvaluationResult) -> dict[str, object]:
    return {
        "policy": result.policy,
        "checkpoint SHA-256": result.checkpoint_sha256 or "(a baseline)",
        "object shapes": list(result.config.target_shapes),
        "seed": result.seed,
        "rooms stepped together": result.num_envs,
        "obstacle counts": [row.obstacles for row in result.results],
        "episodes per count": [row.episodes for row in result.results],
        "wall time [s]": result.wall_seconds,
    }


def _table1(result: EvaluationResult) -> str:
    rows = []
    for row in result.results:
        published = PAPER_TABLE1.get(row.obstacles)
        paper = [None] * 3 if published is None else [f"{v:.1f}" for v in published]
        rows.append([
            row.obstacles, row.episodes, f"{row.coverage_pct:.1f}",
            interval_text(row.strict_coverage_pct, row.strict_coverage_ci), paper[0],
            f"{row.distance_score:.2f}", interval_text(row.crash_pct, row.crash_ci), paper[1],
            f"{row.timeout_pct:.1f}", paper[2],
        ])  # fmt: skip
    headers = (
        "obstacles", "episodes", "coverage %", "strict coverage %", "004", "distance score",
        "crash %", "004", "timeout %", "004",
    )  # fmt: skip
    return rows_table(headers, rows) + (
        "<p>004: the paper's trained policy (Table I). Coverage: lenient, faces seen within "
        "the inspection range; strict, the feasible faces seen by the strict rule. "
        "[ ]: 95 % interval (Student's t; Wilson for crashes).</p>"
    )


def _episodes_table(result: EvaluationResult) -> str:
    rows = [
        (row.obstacles, index + 1, round(coverage, 1), round(strict, 1), feasible,
         "crashed" if crashed else "timeout", length, room)
        for row in result.results
        for index, (coverage, strict, feasible, crashed, length, room) in enumerate(
            zip(row.coverage, row.strict_coverage, row.feasible_faces, row.crashed, row.length,
                row.rooms, strict=True)
        )
    ]  # fmt: skip
    headers = (
        "obstacles", "episode", "coverage %", "strict coverage %", "feasible faces", "ended",
        "steps", "room",
    )  # fmt: skip
    return rows_table(headers, rows)


def coverage_plot(result: EvaluationResult):
    """Mean strict coverage against time per obstacle count, with its 5th-95th percentile band."""
    figure = go.Figure()
    for index, row in enumerate(result.results):
        colour = _COLOURS[index % len(_COLOURS)]
        figure.add_trace(_band_trace(row, colour))
        figure.add_trace(
            go.Scatter(
                x=row.curve_times, y=row.curve_mean, mode="lines", line={"color": colour},
                name=f"{row.obstacles} obstacles (mean of {row.episodes})",
                legendgroup=str(row.obstacles),
                meta={"layer": f"{row.obstacles} obstacles", "nodes": len(row.curve_times)},
            )
        )  # fmt: skip
    figure.update_layout(
        title=f"{result.policy}: strict coverage over the episode (band: 5th-95th percentile)",
        xaxis_title="time [s]", yaxis_title="strict coverage [% of feasible faces]",
        yaxis={"range": [0, 100]},
        height=480,
    )  # fmt: skip
    return figure


def _band_trace(row: ObstacleResult, colour: str):
    """The percentile band as one closed outline (p95 forwards, p5 back)."""
    return go.Scatter(
        x=[*row.curve_times, *row.curve_times[::-1]], y=[*row.curve_p95, *row.curve_p5[::-1]],
        fill="toself", fillcolor=colour, opacity=0.15, line={"width": 0}, hoverinfo="skip",
        name=f"{row.obstacles} obstacles p5-p95", legendgroup=str(row.obstacles),
        showlegend=False,
    )  # fmt: skip


def outcome_plot(result: EvaluationResult):
    """Every episode's final strict coverage per obstacle count; crashed episodes as crosses."""
    figure = go.Figure()
    for ended, symbol in ((False, "circle"), (True, "x")):
        xs, ys, hover = [], [], []
        for row in result.results:
            for index, (coverage, crashed) in enumerate(
                zip(row.strict_coverage, row.crashed, strict=True)
            ):
                if crashed is ended:
                    xs.append(row.obstacles)
                    ys.append(coverage)
                    hover.append(
                        f"{row.obstacles} obstacles, episode {index + 1}: {coverage:.1f} % strict"
                    )
        name = "crashed" if ended else "timeout (no crash)"
        figure.add_trace(
            go.Scatter(
                x=xs, y=ys, mode="markers", name=f"{name} ({len(xs)})", hovertext=hover,
                hoverinfo="text", marker={"symbol": symbol, "size": 8},
                meta={"layer": name, "nodes": len(xs)},
            )
        )  # fmt: skip
    figure.update_layout(
        title="Final strict coverage of every episode", xaxis_title="obstacles",
        yaxis_title="strict coverage [%]", yaxis={"range": [0, 100]}, height=420,
    )  # fmt: skip
    return figure
