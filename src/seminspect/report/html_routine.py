"""``report.html`` of routine inspection (002): a run, a recorded ``M_H``, a ``--compare`` pair.

* A run: the plan on ``M_H`` from above (its walls, the cells that changed in ``M_C``, the
  regions, the planned views in visiting order) with the views Algorithm 1 flew and the path
  driven, one legend entry each; the run's state and figures (002 Sec V), the task table, the
  change report per region, the time series of 002 Figs 8, 9 and 11, and its PNGs.
* A recorded ``M_H`` (``routine map``): its walls from above and its cell counts.
* A ``--compare`` directory: the runs' figures side by side, their time series overlaid and a
  link to each run's own page.
"""

from __future__ import annotations

import html
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import plotly.graph_objects as go
from numpy.typing import NDArray
from plotly.subplots import make_subplots

from seminspect.core.errors import FileFormatError
from seminspect.core.io import read_versioned_json
from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap, load_map
from seminspect.missions.routine.metrics import (
    METRICS_FORMAT,
    RoutineMetrics,
    read_routine_metrics,
)
from seminspect.missions.routine.run import MAP_FILE, TOUR_FORMAT
from seminspect.report.html_page import (
    REPORT_FILE,
    Section,
    document_format,
    key_value_table,
    pictures_section,
    rows_table,
    write_page,
)
from seminspect.report.routine import change_centres, change_maps, load_views, wall_columns
from seminspect.runs.directory import read_run_config
from seminspect.runs.status import read_run_status
from seminspect.runs.trajectory import load_trajectory

ROUTINE_PICTURES = ("performance.png", "changes.png")
COMPARISON_PICTURE = "comparison.png"
#: The time series of 002 Figs 8, 9 and 11: (views.csv columns, panel title).
_SERIES = (
    (("utility",), "viewpoint utility"),
    (("view_distance_m",), "viewing distance [m]"),
    (("gamma_s",), "Γ_s"),
    (("rmse_before_m", "rmse_after_m"), "RMSE to Π_LVP [m]"),
)
#: The figures set side by side on a comparison page.
_COMPARED = (
    ("tasks_completed", "tasks completed"),
    ("viewpoint_utility_mean", "mean viewpoint utility"),
    ("view_distance_mae_m", "viewing-distance MAE [m]"),
    ("roi_coverage_pct", "ROI coverage [%]"),
    ("gamma_s_max", "max Γ_s"),
    ("collisions", "collisions"),
    ("rmse_after_kabsch_m", "RMSE after Kabsch [m]"),
    ("sim_time_s", "simulated time [s]"),
)


def write_routine_report(run_dir: str | os.PathLike[str]) -> Path:
    """``report.html`` of a routine inspection run directory; returns its path."""
    root = Path(run_dir)
    metrics = _metrics(root)
    config = read_run_config(root)
    maps = change_maps(root)
    base, base_name = (maps[0], "M_H") if maps else _current_map(root)
    changes = change_centres(*maps) if maps else None
    plan = plan_figure(
        base, base_name, changes=changes, tours=_tours(root), flown=load_views(root),
        run_dir=root, metrics=metrics,
    )  # fmt: skip
    figures = [("scene", plan), ("performance", performance_plot({root.name: root}))]
    sections = [Section("Run", key_value_table(_run_facts(root, config, metrics)))]
    sections += _metrics_sections(metrics)
    pictures = pictures_section(root, ROUTINE_PICTURES)
    title = f"Routine inspection run {root.name}"
    return write_page(
        root / REPORT_FILE, title, figures, sections, {}, hover_hint=None,
        trailing=[pictures] if pictures else [],
    )  # fmt: skip


def write_routine_map_report(run_dir: str | os.PathLike[str]) -> Path:
    """``report.html`` of a directory ``routine map`` wrote: ``M_H`` from above, its cells."""
    root = Path(run_dir)
    prior = load_map(root / MAP_FILE)
    figure = plan_figure(prior, "M_H", title="M_H from above")
    facts = {**_status_facts(root), "program": "routine map (002): M_H recorded"}
    sections = [Section("Run", key_value_table(facts)), Section("M_H", _map_table(prior))]
    title = f"Historical map {root.name}"
    return write_page(root / REPORT_FILE, title, [("scene", figure)], sections, {}, hover_hint=None)


def write_routine_comparison_report(out_dir: str | os.PathLike[str]) -> Path:
    """``report.html`` of a ``--compare`` directory (one routine run per subdirectory): their
    figures side by side, the time series overlaid, links to each run's page (written first
    where a run has none)."""
    root = Path(out_dir)
    runs = {path.name: path for path in routine_runs_below(root)}
    for run in runs.values():
        if not (run / REPORT_FILE).is_file():
            write_routine_report(run)
    links = "".join(
        f'<li><a href="{html.escape(name)}/{REPORT_FILE}">{html.escape(name)}</a></li>'
        for name in runs
    )
    sections = [Section("Runs", f"<ul>{links}</ul>"), Section("Figures", _comparison_table(runs))]
    pictures = pictures_section(root, (COMPARISON_PICTURE,))
    figures = [("performance", performance_plot(runs))]
    title = f"Routine inspection: {' vs '.join(runs)}"
    return write_page(
        root / REPORT_FILE, title, figures, sections, {}, hover_hint=None,
        trailing=[pictures] if pictures else [],
    )  # fmt: skip


def is_routine_run(root: Path) -> bool:
    """A routine inspection run: metrics tagged as one, or (stopped early) its tour file."""
    metrics, tour = root / "metrics.json", root / "tour.json"
    return (metrics.is_file() and document_format(metrics) == METRICS_FORMAT) or (
        tour.is_file() and document_format(tour) == TOUR_FORMAT
    )


def is_routine_map(root: Path) -> bool:
    """A directory ``routine map`` wrote (its config says so, and the map is there)."""
    if not ((root / "config.json").is_file() and (root / MAP_FILE).is_file()):
        return False
    try:
        return "routine_map" in read_run_config(root)
    except FileFormatError:
        return False


def routine_runs_below(root: Path) -> list[Path]:
    """The routine runs directly below ``root`` (a ``--compare`` directory), by name."""
    children = sorted(p for p in root.iterdir() if p.is_dir())
    return [child for child in children if is_routine_run(child)]


# --- the pieces of a run's page ----------------------------------------------------------------


def _metrics(root: Path) -> RoutineMetrics | None:
    if not (root / "metrics.json").is_file():
        return None
    return read_routine_metrics(root)


def _current_map(root: Path) -> tuple[VoxelMap | None, str]:
    """M_C when M_H cannot be drawn (its file is no .npz, or its grid differs)."""
    path = root / MAP_FILE
    return (load_map(path), "M_C") if path.is_file() else (None, "")


def _tours(root: Path) -> list[dict[str, Any]]:
    path = root / "tour.json"
    return read_versioned_json(path, TOUR_FORMAT, [1])["tasks"] if path.is_file() else []


def _status_facts(root: Path) -> dict[str, Any]:
    if not (root / "status.json").is_file():
        return {"state": "unknown (no status.json)"}
    status = read_run_status(root)
    return {"state": status.state, "reason": status.reason}


def _run_facts(root: Path, config: Mapping[str, Any], metrics: RoutineMetrics | None):
    mode = "adaptive (Algorithm 1)" if config.get("adapt", True) else "non-adaptive baseline"
    facts: dict[str, Any] = {**_status_facts(root), "program": f"routine inspection (002), {mode}"}
    if metrics is not None:
        scenario = metrics.scenario
        facts["scenario"] = {"name": scenario.name, "seed": scenario.seed, **scenario.change}
    facts["M_H"] = config.get("prior") or "recorded by this run (prior/map.npz)"
    facts["tasks file"] = config.get("tasks") or "the scenario's"
    return facts


def _metrics_sections(metrics: RoutineMetrics | None) -> list[Section]:
    if metrics is None:
        return [Section("Figures", "<p>This run wrote no metrics (it may have been stopped).</p>")]
    scalars = {
        key: value
        for key, value in metrics.to_json().items()
        if not isinstance(value, dict | list) and key not in ("state", "stop_reason")
    }
    tasks = rows_table(
        ("task", "completed", "skipped", "views planned", "repaired", "dropped", "tracked",
         "route [m]", "coverage [%]", "time [s]", "SA tour [m]", "reference tour [m]", "gap [%]"),
        [
            (t.name, t.completed, t.skipped or "-", t.views_planned, t.views_repaired,
             t.views_dropped, t.views_tracked, t.route_length_m, t.coverage_pct, t.time_s,
             t.tour.get("sa_length_m"), t.tour.get("reference_length_m"), t.tour.get("gap_pct"))
            for t in metrics.tasks
        ],
    )  # fmt: skip
    changes = rows_table(
        ("region", "added [m³]", "removed [m³]", "compared [m³]"),
        [(c.region, c.added_m3, c.removed_m3, c.compared_m3) for c in metrics.change_report],
    )
    return [
        Section("Figures (002 Sec V)", key_value_table(scalars)),
        Section("Tasks", tasks),
        Section("Change report (M_C against M_H, per region)", changes),
    ]


def _map_table(voxels: VoxelMap) -> str:
    counts = {
        name: int((voxels.states == state).sum())
        for name, state in (("occupied cells", OCCUPIED), ("free cells", FREE),
                            ("unknown cells", UNKNOWN))
    }  # fmt: skip
    extent = [f"{lo:.2f} to {hi:.2f}" for lo, hi in zip(voxels.origin, voxels.upper, strict=True)]
    return key_value_table(
        {**counts, "resolution [m]": voxels.resolution, "x [m]": extent[0], "y [m]": extent[1],
         "z [m]": extent[2]}
    )  # fmt: skip


def _comparison_table(runs: Mapping[str, Path]) -> str:
    metrics = {name: _metrics(path) for name, path in runs.items()}
    rows = [
        (label, *[None if m is None else getattr(m, key) for m in metrics.values()])
        for key, label in _COMPARED
    ]
    states = ("state", *[_status_facts(path)["state"] for path in runs.values()])
    return rows_table(("", *runs), [states, *rows])


# --- figures -----------------------------------------------------------------------------------


def plan_figure(
    base: VoxelMap | None,
    base_name: str,
    *,
    changes: Mapping[str, NDArray] | None = None,
    tours: Sequence[Mapping[str, Any]] = (),
    flown: Mapping[str, NDArray] | None = None,
    run_dir: Path | None = None,
    metrics: RoutineMetrics | None = None,
    title: str = "Plan on M_H and the run, from above",
):
    """The site from above: a map's walls, what changed, regions, views, and the path."""
    figure = go.Figure()
    if base is not None:
        figure.add_trace(_walls_trace(base, base_name))
    for name, colour in (("added", "#d62728"), ("removed", "#1f77b4")):
        if changes is not None:
            figure.add_trace(_cells_trace(changes[name], f"{name} in M_C", colour))
    if tours:
        figure.add_trace(_regions_trace(tours))
        figure.add_trace(_region_names_trace(tours, metrics))
        figure.add_trace(_tour_trace(tours))
        figure.add_trace(_views_trace(tours))
    if flown:
        figure.add_trace(_flown_trace(flown))
    trajectory = load_trajectory(run_dir) if run_dir is not None else np.empty((0, 9))
    if len(trajectory):
        figure.add_trace(_path_trace(trajectory))
    figure.update_layout(
        title=f"{title} (click a legend entry to toggle it)",
        xaxis_title="x [m]", yaxis_title="y [m]", yaxis={"scaleanchor": "x"}, height=560,
        legend={"itemsizing": "constant"}, plot_bgcolor="white",
    )  # fmt: skip
    return figure


def _counted(name: str, count: int) -> dict[str, Any]:
    return {"layer": name, "nodes": count}


def _walls_trace(voxels: VoxelMap, name: str):
    walls = wall_columns(voxels)
    x = voxels.origin[0] + (np.arange(walls.shape[1]) + 0.5) * voxels.resolution
    y = voxels.origin[1] + (np.arange(walls.shape[0]) + 0.5) * voxels.resolution
    return go.Heatmap(
        z=walls.astype(np.uint8), x=x, y=y, colorscale=[[0, "rgba(0,0,0,0)"], [1, "#9a9a9a"]],
        showscale=False, hoverinfo="skip", name=f"{name} walls", showlegend=True,
        meta=_counted(f"{name} walls", int(walls.sum())),
    )  # fmt: skip


def _cells_trace(centres: NDArray, name: str, colour: str):
    return go.Scatter(
        x=centres[:, 0], y=centres[:, 1], mode="markers", name=f"{name} ({len(centres)})",
        marker={"size": 3, "color": colour, "symbol": "square"}, hoverinfo="skip",
        meta=_counted(name, len(centres)),
    )  # fmt: skip


def _regions_trace(tours: Sequence[Mapping[str, Any]]):
    xs: list[float | None] = []
    ys: list[float | None] = []
    for task in tours:
        ring = np.array(task["region"] + task["region"][:1])
        xs += [*ring[:, 0].tolist(), None]
        ys += [*ring[:, 1].tolist(), None]
    return go.Scatter(
        x=xs, y=ys, mode="lines", name="regions", hoverinfo="skip",
        line={"color": "black", "width": 2, "dash": "dash"},
    )  # fmt: skip


def _region_names_trace(tours: Sequence[Mapping[str, Any]], metrics: RoutineMetrics | None):
    records = {t.name: t for t in metrics.tasks} if metrics is not None else {}
    changes = {c.region: c for c in metrics.change_report} if metrics is not None else {}
    centres = np.array([np.mean(np.array(task["region"])[:, :2], axis=0) for task in tours])
    hover = []
    for task in tours:
        lines = [f"<b>{html.escape(task['task'])}</b>", f"{len(task['views'])} views planned"]
        if (record := records.get(task["task"])) is not None:
            done = "completed" if record.completed else f"not completed {record.skipped}"
            lines += [done, f"coverage: {_num(record.coverage_pct)} %"]
        if (change := changes.get(task["task"])) is not None:
            lines.append(f"added {change.added_m3:.2f} m³, removed {change.removed_m3:.2f} m³")
        hover.append("<br>".join(lines))
    return go.Scatter(
        x=centres[:, 0], y=centres[:, 1], mode="markers+text", name=f"Regions ({len(tours)})",
        text=[task["task"] for task in tours], textposition="top center", hovertext=hover,
        hoverinfo="text", marker={"size": 9, "color": "black", "symbol": "x"},
        meta=_counted("Regions", len(tours)),
    )  # fmt: skip


def _tour_trace(tours: Sequence[Mapping[str, Any]]):
    xs: list[float | None] = []
    ys: list[float | None] = []
    for task in tours:
        views = np.array(task["views"]).reshape(-1, 3)
        xs += [*views[:, 0].tolist(), None]
        ys += [*views[:, 1].tolist(), None]
    return go.Scatter(
        x=xs, y=ys, mode="lines", name="tour (visiting order)", hoverinfo="skip",
        line={"color": "#ff7f0e", "width": 1},
    )  # fmt: skip


def _views_trace(tours: Sequence[Mapping[str, Any]]):
    rows, hover, order = [], [], []
    for task in tours:
        views = np.array(task["views"]).reshape(-1, 3)
        for k, (view, yaw) in enumerate(zip(views, task["yaws"], strict=True)):
            rows.append(view)
            order.append(str(k + 1))
            hover.append(
                f"<b>{html.escape(task['task'])}</b> view {k + 1} of {len(views)}<br>"
                f"x {view[0]:.2f}, y {view[1]:.2f}, z {view[2]:.2f} m<br>"
                f"yaw {np.degrees(yaw):.0f}°"
            )
    xyz = np.array(rows).reshape(-1, 3)
    return go.Scatter(
        x=xyz[:, 0], y=xyz[:, 1], mode="markers+text", name=f"Planned views ({len(xyz)})",
        text=order, textposition="bottom center", textfont={"size": 9}, hovertext=hover,
        hoverinfo="text", marker={"size": 7, "color": "#ff7f0e"},
        meta=_counted("Planned views", len(xyz)),
    )  # fmt: skip


def _flown_trace(views: Mapping[str, NDArray]):
    hover = [
        f"t {t:.1f} s<br>utility {u:.2f}, distance {d:.2f} m<br>Γ_s {g:.2f}"
        f"{' (adapted)' if adapted else ''}"
        for t, u, d, g, adapted in zip(
            views["t"], views["utility"], views["view_distance_m"], views["gamma_s"],
            views["adapted"], strict=True,
        )
    ]  # fmt: skip
    count = len(views["t"])
    return go.Scatter(
        x=views["x"], y=views["y"], mode="markers", name=f"Views flown ({count})",
        hovertext=hover, hoverinfo="text",
        marker={"size": 8, "color": "rgba(0,0,0,0)", "line": {"color": "#2ca02c", "width": 2}},
        meta=_counted("Views flown", count),
    )  # fmt: skip


def _path_trace(trajectory: NDArray):
    return go.Scatter(
        x=trajectory[:, 1], y=trajectory[:, 2], mode="lines", name="path (true)",
        line={"color": "#2ca02c", "width": 1.5}, text=trajectory[:, 0],
        hovertemplate="t=%{text:.1f} s<br>x=%{x:.2f} y=%{y:.2f}<extra></extra>",
    )  # fmt: skip


def performance_plot(runs: Mapping[str, Path]):
    """Utility, viewing distance against d_view, Γ_s against Γ_t and the RMSE before and after
    Kabsch over time (002 Figs 8, 9, 11), each run's lines in its own colour."""
    titles = [title for _, title in _SERIES]
    figure = make_subplots(rows=len(_SERIES), cols=1, shared_xaxes=True, subplot_titles=titles)
    for name, root in runs.items():
        views = load_views(root)
        if not views:
            continue
        for row, (columns, _) in enumerate(_SERIES, start=1):
            for column in columns:
                dash = "dash" if column == "rmse_after_m" else "solid"
                label = f"{name} {column}" if len(runs) > 1 else column
                figure.add_trace(
                    go.Scatter(
                        x=views["t"], y=views[column], mode="lines+markers", name=label,
                        line={"dash": dash}, legendgroup=name or column,
                        meta=_counted(label, len(views["t"])),
                    ), row=row, col=1,
                )  # fmt: skip
    config = read_run_config(next(iter(runs.values())))
    figure.add_hline(y=config["d_view"], line_dash="dot", line_color="grey", row=2, col=1)
    figure.add_hline(y=config["gamma_t"], line_dash="dot", line_color="grey", row=3, col=1)
    figure.update_layout(
        title="Algorithm 1 cycles over time (dotted: d_view and Γ_t)", height=900,
    )  # fmt: skip
    figure.update_xaxes(title_text="simulated time [s]", row=len(_SERIES), col=1)
    return figure


def _num(value: float | None) -> str:
    return "-" if value is None else f"{value:.1f}"
