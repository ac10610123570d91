"""The live view of a routine mission (002): its page and the states it draws.

The page (:func:`routine_page`, on :func:`~seminspect.report.live_common.stream_page`) shows in
3D the old map ``M_H`` and the map the robot builds now, ``M_C``, side by side (where they
differ is the site's change), every region with its planned views, the task being toured with
its views in visiting order coloured by outcome, the poses the views were taken from (off the
plan where Algorithm 1 adapted), the path and the robot; beside it the last view's camera frame
and the status: simulated time, the task and its coverage, the last cycle's ``Γ_s`` against
``Γ_t``, the viewpoint's utility and distance. :class:`RoutineFeed` turns each
:class:`~seminspect.missions.routine.live.LiveState` into one JSON message for a
:class:`~seminspect.report.live_server.LiveServer`.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from seminspect.missions.routine.live import ActiveView, LiveScene, LiveState
from seminspect.report.live_common import (
    MAP_PERIOD_S,
    camera_picture,
    occupied_points,
    polylines,
    scatter,
    stream_page,
    trail,
    xyz,
)
from seminspect.report.live_server import LiveServer

#: Marker colours of the toured views: not yet, tracked, unreachable.
PENDING, TRACKED, UNREACHABLE = "#ff7f0e", "#2ca02c", "#d62728"
_PHASES = {"start": "starting", "navigate": "navigating to", "tour": "touring", "done": "done"}


def routine_page(title: str) -> str:
    """The page: the scene's traces empty (the stream fills them), the camera and the status."""
    traces = [
        scatter("M_H", marker={"size": 1.5, "color": "#6baed6", "opacity": 0.35}),
        scatter("M_C", marker={"size": 1.5, "color": "#8c564b", "opacity": 0.6}),
        scatter("regions", mode="lines", line={"color": "#9467bd", "width": 4}),
        scatter("planned views", hover=True, marker={"size": 2.5, "color": "#7f7f7f"}),
        scatter(
            "tour",
            mode="lines+markers",
            hover=True,
            line={"color": PENDING, "width": 2},
            marker={"size": 4, "color": PENDING},
        ),
        scatter("views flown", marker={"size": 4, "symbol": "diamond", "color": "#17becf"}),
        scatter("path", mode="lines", line={"color": "#1f77b4", "width": 3}),
        scatter("robot", marker={"symbol": "diamond", "size": 7, "color": "black"}),
    ]
    heading = "Live: M_H and M_C, the regions, the tour and the path"
    return stream_page(title, heading, traces, "the camera's last view")


def scene_message(scene: LiveScene) -> dict[str, Any]:
    """The static part of the view: ``M_H`` (subsampled), region outlines, planned views."""
    outlines = [np.vstack([t.outline, t.outline[:1]]) for t in scene.tasks]
    views = [t.views for t in scene.tasks]
    text = [f"{t.name}: view {k + 1} of {len(t.views)}" for t in scene.tasks
            for k in range(len(t.views))]  # fmt: skip
    planned = xyz(np.vstack(views) if views else np.empty((0, 3)))
    return {
        "traces": {
            "M_H": xyz(occupied_points(scene.prior)),
            "regions": polylines(outlines),
            "planned views": {**planned, "text": text},
        },
        "tasks": [t.name for t in scene.tasks],
    }


class RoutineFeed:
    """A routine mission's live states for ``server``, paced by it (a ``LiveFeed``)."""

    def __init__(self, server: LiveServer) -> None:
        self.server = server
        self._map_points = xyz(np.empty((0, 3)))
        self._map_at = -float("inf")
        self._started = time.monotonic()

    def start(self, scene: LiveScene) -> None:
        self.server.set_scene(scene_message(scene))
        self._started = time.monotonic()

    def ready(self) -> bool:
        return self.server.ready()

    def publish(self, state: LiveState) -> None:
        self.server.send(self.message(state))

    def message(self, state: LiveState) -> dict[str, Any]:
        """One state as the page's JSON (see :mod:`~seminspect.report.live_common`)."""
        if time.monotonic() - self._map_at >= MAP_PERIOD_S or state.ended:
            self._map_points = xyz(occupied_points(state.current_map))
            self._map_at = time.monotonic()
        task, cycle = state.task, state.last_cycle
        return {
            "t": round(state.sim_time, 2),
            "pose": np.round(state.trajectory[-1, 1:5], 3).tolist(),
            "phase": state.phase,
            "task": None if task is None else task.name,
            "outcomes": [] if task is None else list(task.outcomes),
            "coverage": _rounded(None if task is None else task.coverage_pct),
            "gamma_s": _rounded(None if cycle is None else cycle.gamma_s),
            "adapted": None if cycle is None else bool(cycle.adapted),
            "traces": {
                "M_C": self._map_points,
                "path": xyz(trail(state.trajectory[:, 1:4])),
                "tour": _tour(task),
                "views flown": xyz(np.empty((0, 3)) if task is None else task.flown),
            },
            "image": None if state.frame is None else camera_picture(state.frame, []),
            "caption": _caption(state),
            "status": self._status(state),
            "final": None if state.ended is None else f"run {state.ended}: {state.reason}",
        }

    def _status(self, state: LiveState) -> list[list[str]]:
        wall = time.monotonic() - self._started
        speed = f" ({state.sim_time / wall:.1f}x real time)" if wall > 0 else ""
        task = state.task
        rows = [
            ["simulated", f"{state.sim_time:.1f} s{speed}"],
            ["phase", _phase(state)],
            ["tasks completed", f"{state.tasks_done} / {state.tasks_total}"],
        ]
        if task is not None:
            rows += [
                ["task", f"{task.name} ({task.index + 1} of {state.tasks_total})"],
                ["views", _views(task)],
                ["ROI coverage", _pct(task.coverage_pct)],
            ]
        rows += [["last cycle", _decision(state)], ["viewpoint", _viewpoint(state)]]
        rows.append(["collisions", str(state.collisions)])
        if state.ended is not None:
            rows.append(["run", f"{state.ended}: {state.reason}"])
        return rows


def _tour(task: ActiveView | None) -> dict[str, list]:
    """The toured task's views in visiting order, coloured by outcome (empty before its tour)."""
    if task is None or not task.toured:
        return {**xyz(np.empty((0, 3))), "color": [], "text": []}
    colours = {None: PENDING, True: TRACKED, False: UNREACHABLE}
    words = {None: "to go", True: "tracked", False: "unreachable"}
    count = len(task.views)
    return {
        **xyz(task.views),
        "color": [colours[o] for o in task.outcomes],
        "text": [
            f"{task.name}: tour pose {k + 1} of {count}, {words[o]}"
            for k, o in enumerate(task.outcomes)
        ],
    }


def _phase(state: LiveState) -> str:
    words = _PHASES.get(state.phase, state.phase)
    return words if state.task is None or state.phase == "done" else f"{words} {state.task.name}"


def _views(task: ActiveView) -> str:
    tracked = sum(o is True for o in task.outcomes)
    lost = sum(o is False for o in task.outcomes)
    left = sum(o is None for o in task.outcomes)
    return f"{tracked} tracked, {lost} unreachable, {left} to go (of {len(task.outcomes)})"


def _decision(state: LiveState) -> str:
    cycle = state.last_cycle
    if cycle is None:
        return "-"
    above = cycle.gamma_s > state.gamma_t
    sign = ">" if above else "<="
    chose = "tracked Π_LVP (adapted)" if cycle.adapted else "tracked the global pose"
    return f"Γ_s {cycle.gamma_s:.2f} {sign} Γ_t {state.gamma_t:.2f}: {chose}"


def _viewpoint(state: LiveState) -> str:
    cycle = state.last_cycle
    if cycle is None:
        return "-"
    distance = "-" if not np.isfinite(cycle.view_distance_m) else f"{cycle.view_distance_m:.2f} m"
    return f"utility {cycle.utility:.2f}, viewing distance {distance}"


def _caption(state: LiveState) -> str:
    if state.frame is None:
        return "camera: no view taken yet"
    return f"camera: the last view, t = {state.frame.stamp:.1f} s"


def _pct(value: float | None) -> str:
    return "-" if value is None else f"{value:.1f} %"


def _rounded(value: float | None) -> float | None:
    return None if value is None or not np.isfinite(value) else round(float(value), 4)
