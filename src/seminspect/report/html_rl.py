"""``report.html`` of an ``rl eval`` directory (004): coverage over time, outcomes, episodes.

Drawn from ``evaluation.json`` alone (and the PNGs beside it): the mean coverage against time
per obstacle count with its 5th-95th percentile band (004 Fig 5), every episode's final
coverage, the table beside 004 Table I, one row per episode, and the evaluation's pictures.
"""

from __future__ import annotations

import os
from pathlib import Path

import plotly.graph_objects as go

from seminspect.missions.learning.evaluation import PAPER_TABLE1, EvaluationResult, ObstacleResult
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
        "seed": result.seed,
        "rooms stepped together": result.num_envs,
        "obstacle counts": [row.obstacles for row in result.results],
        "episodes per count": [row.episodes for row in result.results],
        "wall time [s]": result.wall_seconds,
    }


def _table1(result: EvaluationResult) -> str:
    rows = []
    for row in result.results:
        paper = PAPER_TABLE1.get(row.obstacles)
        cells: list[object] = [row.obstacles, row.episodes]
        for k, ours in enumerate((row.coverage_pct, row.crash_pct, row.timeout_pct)):
            cells += [round(ours, 1), None if paper is None else paper[k]]
        rows.append(cells)
    headers = ("obstacles", "episodes", "coverage %", "004", "crash %", "004", "timeout %", "004")
    return rows_table(headers, rows) + "<p>004: the paper's trained policy (Table I).</p>"


def _episodes_table(result: EvaluationResult) -> str:
    rows = [
        (row.obstacles, index + 1, round(coverage, 1), "crashed" if crashed else "timeout",
         length, room)
        for row in result.results
        for index, (coverage, crashed, length, room) in enumerate(
            zip(row.coverage, row.crashed, row.length, row.rooms, strict=True)
        )
    ]  # fmt: skip
    headers = ("obstacles", "episode", "final coverage %", "ended", "steps", "room")
    return rows_table(headers, rows)


def coverage_plot(result: EvaluationResult):
    """Mean coverage against time per obstacle count, with its 5th-95th percentile band."""
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
        title=f"{result.policy}: coverage over the episode (band: 5th-95th percentile)",
        xaxis_title="time [s]", yaxis_title="coverage [%]", yaxis={"range": [0, 100]},
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
    """Every episode's final coverage per obstacle count; crashed episodes as crosses."""
    figure = go.Figure()
    for ended, symbol in ((False, "circle"), (True, "x")):
        xs, ys, hover = [], [], []
        for row in result.results:
            for index, (coverage, crashed) in enumerate(
                zip(row.coverage, row.crashed, strict=True)
            ):
                if crashed is ended:
                    xs.append(row.obstacles)
                    ys.append(coverage)
                    hover.append(
                        f"{row.obstacles} obstacles, episode {index + 1}: {coverage:.1f} %"
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
        title="Final coverage of every episode", xaxis_title="obstacles",
        yaxis_title="coverage [%]", yaxis={"range": [0, 100]}, height=420,
    )  # fmt: skip
    return figure
