"""Pictures of a run, drawn from its run directory alone (so interrupted runs get them too).

* ``trajectory.png``: the robot's true and believed path over the top-down world, with the
  targets it found (inspected ones with their containment polygons);
* ``graph.png``: the final 3DLSG's layers stacked above the world's footprints (000 Figs 2, 12);
* ``utility.png``: eq (6) for every candidate at every decision, the chosen one marked;
* ``timeline.png`` (team runs): what each robot did when, from its ``activity`` events.

A team run's trajectory picture draws every robot's true path in a colour of its own.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.io import load_graph
from seminspect.missions.xflie.layout import load_run_world
from seminspect.report.figures import new_figure, save_figure
from seminspect.report.lsg import draw_layers
from seminspect.report.worlds import draw_top_down
from seminspect.runs.directory import load_events
from seminspect.runs.trajectory import load_robot_trajectories, load_trajectory
from seminspect.worlds import World

#: Colours of a team's robots and of their activities on the timeline.
ROBOT_COLOURS = {"explorer": "tab:green", "inspector": "tab:purple"}
ACTIVITY_COLOURS = {
    "survey": "tab:green", "explore": "tab:olive", "inspect": "tab:purple",
    "skip": "tab:orange", "wait": "lightgrey",
}  # fmt: skip


def trajectory_figure(
    world: World,
    graph: LayeredSemanticGraph,
    trajectory: np.ndarray,
    robots: Mapping[str, np.ndarray] | None = None,
):
    """The path over the world with the targets; a team's ``robots`` paths replace the one."""
    figure = new_figure(12, 8)
    ax = figure.add_subplot()
    draw_top_down(world, ax)
    for name, path in (robots or {}).items():
        colour = ROBOT_COLOURS.get(name, "tab:blue")
        ax.plot(path[:, 1], path[:, 2], color=colour, linewidth=1.2, label=f"{name} (true)")
    if len(trajectory) and not robots:
        ax.plot(
            trajectory[:, 1], trajectory[:, 2], color="tab:blue", linewidth=1.2, label="path (true)"
        )
        ax.plot(
            trajectory[:, 5],
            trajectory[:, 6],
            color="tab:cyan",
            linewidth=0.8,
            linestyle="--",
            label="path (odometry)",
        )
    for target in graph.targets():
        colour = "tab:red" if target.inspected else "tab:orange"
        ax.plot(*target.position[:2], marker="o", color=colour, markersize=6)
        ax.annotate(
            target.id,
            tuple(target.position[:2]),
            fontsize=7,
            color=colour,
            xytext=(4, 4),
            textcoords="offset points",
        )
        if target.polygon is not None:
            ring = np.vstack([target.polygon, target.polygon[:1]])
            ax.plot(ring[:, 0], ring[:, 1], color=colour, linewidth=0.8)
    ax.plot([], [], marker="o", color="tab:red", linestyle="", label="inspected target")
    ax.plot([], [], marker="o", color="tab:orange", linestyle="", label="detected target")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title("Trajectory and targets")
    return figure


def utility_series(
    events: list[dict],
) -> tuple[dict[str, list[tuple[float, float]]], list[tuple[float, float]]]:
    """``(time, U)`` per target over every decision, and the ``(time, U)`` of each choice."""
    series: dict[str, list[tuple[float, float]]] = {}
    chosen: list[tuple[float, float]] = []
    for event in events:
        if event.get("event") != "utilities":
            continue
        for target, terms in event["terms"].items():
            series.setdefault(target, []).append((event["t"], terms[0]))
            if target == event.get("chosen"):
                chosen.append((event["t"], terms[0]))
    return series, chosen


def utility_figure(events: list[dict]):
    figure = new_figure(10, 5)
    ax = figure.add_subplot()
    series, chosen = utility_series(events)
    for target, points in sorted(series.items()):
        data = np.array(points)
        ax.plot(data[:, 0], data[:, 1], marker=".", linewidth=0.8, label=target)
    if chosen:
        data = np.array(chosen)
        ax.scatter(
            data[:, 0],
            data[:, 1],
            s=90,
            facecolors="none",
            edgecolors="black",
            label="selected (argmax)",
        )
    ax.set_xlabel("simulated time [s]")
    ax.set_ylabel("utility U (eq 6)")
    ax.set_title("Target selection over time")
    if series:
        ax.legend(fontsize=7, ncol=2, loc="upper right")
    return figure


def timeline_figure(events: list[dict]):
    """One row per robot: a bar for each step, coloured by what it did."""
    steps = [e for e in events if e.get("event") == "activity"]
    robots = sorted({e["robot"] for e in steps}, key=list(ROBOT_COLOURS).index)
    figure = new_figure(12, 1.2 + 0.8 * len(robots))
    ax = figure.add_subplot()
    for row, robot in enumerate(robots):
        for step in (e for e in steps if e["robot"] == robot):
            ax.barh(
                row,
                step["end"] - step["start"],
                left=step["start"],
                color=ACTIVITY_COLOURS.get(step["activity"], "tab:blue"),
                edgecolor="white",
                linewidth=0.3,
            )
    for activity, colour in ACTIVITY_COLOURS.items():
        ax.barh(0, 0, color=colour, label=activity)
    ax.set_yticks(range(len(robots)), robots)
    ax.set_xlabel("simulated time [s]")
    ax.set_title("What each robot did when")
    ax.set_ylim(-0.5, len(robots) + 0.3)  # headroom for the legend above the rows
    ax.legend(fontsize=7, ncol=len(ACTIVITY_COLOURS), loc="upper center")
    return figure


def render_run(run_dir: str | os.PathLike[str]) -> list[Path]:
    """Draw every picture of a run into its directory; returns the files written."""
    root = Path(run_dir)
    world = load_run_world(root)
    graph = load_graph(root / "graph.json")
    footprints = [
        np.asarray(info.footprint.exterior.coords)[:-1] for info in world.instances.values()
    ]
    events = load_events(root)
    robots = load_robot_trajectories(root)
    written = [
        save_figure(
            trajectory_figure(world, graph, load_trajectory(root), robots),
            root / "trajectory.png",
        ),
        save_figure(draw_layers(graph, footprints), root / "graph.png"),
        save_figure(utility_figure(events), root / "utility.png"),
    ]
    if robots:
        written.append(save_figure(timeline_figure(events), root / "timeline.png"))
    return written
