"""Pictures of the learned-inspection rooms (004): one episode, and coverage against time.

* :func:`episode_top_down`: the room from above, obstacles as their footprints, the path, and
  the target's faces from above, ringed by 12 sectors shaded by the share of the faces facing
  their way that are covered;
* :func:`episode_3d`: the same episode in 3D, every target face coloured by its coverage;
* :func:`coverage_figure`: strict coverage (of the feasible faces) over the episode, one panel
  per obstacle count, one line (mean, with the 5th-95th percentile band and the 95 % and 100 %
  lines of 004 Fig 5) per evaluated controller.

A face is covered when its best viewing distance d_f is within the inspection range; seen
but only from farther is drawn apart from never seen.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PolyCollection
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Patch, Polygon, Rectangle, Wedge
from numpy.typing import NDArray
from scipy.spatial import ConvexHull

from seminspect.missions.learning.env import EnvConfig
from seminspect.missions.learning.evaluation import EpisodeTrace, EvaluationResult
from seminspect.missions.learning.rooms import BOX, CYLINDER, Room
from seminspect.report.figures import new_figure, save_figure

COVERED, FAR, UNSEEN = "tab:green", "tab:orange", "tab:red"


def face_states(face_distances: NDArray[np.float64], inspect_range: float) -> NDArray[np.int8]:
    """Per target face: 2 covered (d_f within range), 1 seen only from farther, 0 never seen."""
    seen = np.isfinite(face_distances)
    return np.where(face_distances <= inspect_range, 2, np.where(seen, 1, 0)).astype(np.int8)


def solid_outline(kind: int, centre, rotation, size) -> NDArray[np.float64]:
    """Top-down outline (convex polygon, ``(M, 2)``) of a box or cylinder of a room."""
    if kind == BOX:
        corners = np.array(np.meshgrid(*[[-1.0, 1.0]] * 3)).reshape(3, -1).T * size
    else:  # CYLINDER: two rims along its local z axis
        angle = np.linspace(0.0, 2.0 * math.pi, 24, endpoint=False)
        rim = np.stack([size[0] * np.cos(angle), size[0] * np.sin(angle)], axis=1)
        corners = np.vstack([np.column_stack([rim, np.full(24, z)]) for z in (-size[1], size[1])])
    points = (corners @ np.asarray(rotation).T + centre)[:, :2]
    return points[ConvexHull(points).vertices]


def _draw_obstacles(ax: Axes, room: Room) -> None:
    solids = room.solids
    for k in range(room.target_solids, len(solids.kind)):
        kind, centre = int(solids.kind[k]), solids.centre[k]
        shape: Patch
        if kind in {BOX, CYLINDER}:
            shape = Polygon(solid_outline(kind, centre, solids.rotation[k], solids.size[k]))
        else:
            shape = Circle(tuple(centre[:2]), solids.size[k, 0])
        shape.set(facecolor="0.6", edgecolor="0.3", alpha=0.7, linewidth=0.8)
        ax.add_patch(shape)


def _draw_target(ax: Axes, room: Room, states: NDArray[np.int8]) -> None:
    """The target's triangles from above (higher ones over lower ones), coloured by their
    face's state, ringed by 12 wedges, each shaded by the share of covered faces facing
    its way (so the sides, hidden from above, show too)."""
    on = np.flatnonzero(room.face_of_triangle >= 0)
    corners, faces = room.vertices[room.triangles[on]], room.face_of_triangle[on]
    order = np.argsort(corners[:, :, 2].max(axis=1))
    palette = np.array([to_rgba(c) for c in (UNSEEN, FAR, COVERED)])
    triangles = PolyCollection(
        list(corners[order, :, :2]), facecolors=palette[states[faces[order]]]
    )
    triangles.set(edgecolor="0.2", linewidth=0.2)
    ax.add_collection(triangles)
    centre = room.target_box.mean(axis=0)
    sector = _face_sectors(corners, faces, len(states), centre)
    green, red = np.array(to_rgba(COVERED)), np.array(to_rgba(UNSEEN))
    for s in np.unique(sector):
        share = float((states[sector == s] == 2).mean())
        wedge = Wedge(
            tuple(centre[:2]), room.target_radius + 0.3, 30.0 * s, 30.0 * (s + 1), width=0.2
        )
        wedge.set(facecolor=share * green + (1.0 - share) * red, edgecolor="black", linewidth=0.5)
        ax.add_patch(wedge)


def _face_sectors(corners: NDArray, faces: NDArray, count: int, centre: NDArray) -> NDArray:
    """The 30-degree sector (0..11) about ``centre`` of each face's area-weighted centroid."""
    area = np.linalg.norm(
        np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1
    )
    middle = corners.mean(axis=1)
    total = np.bincount(faces, area, count)
    x, y = (np.bincount(faces, area * middle[:, i], count) / total - centre[i] for i in (0, 1))
    return (np.degrees(np.arctan2(y, x)) % 360.0 // 30.0).astype(int)


def episode_top_down(trace: EpisodeTrace, inspect_range: float, title: str = "") -> Figure:
    """The episode from above: room, obstacle footprints, path and the target's coverage."""
    room, track = trace.room, trace.track
    states = face_states(trace.face_distances, inspect_range)
    figure = new_figure(7, 7)
    ax = figure.add_subplot()
    ax.add_patch(Rectangle((0, 0), room.size[0], room.size[1], fill=False, linewidth=1.5))
    _draw_obstacles(ax, room)
    _draw_target(ax, room, states)
    ax.plot(track[:, 0], track[:, 1], color="tab:blue", linewidth=1.0, label="path")
    ax.plot(*track[0, :2], marker="o", color="tab:blue", linestyle="", label="start")
    end_marker, end_label = ("x", "crash") if trace.crashed else ("s", "end")
    ax.plot(*track[-1, :2], marker=end_marker, color="black", linestyle="", label=end_label)
    ax.set_aspect("equal")
    ax.set_xlim(-0.3, room.size[0] + 0.3)
    ax.set_ylim(-0.3, room.size[1] + 0.3)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    covered = int((states == 2).sum())
    ax.set_title(f"{title}  coverage {covered}/{len(states)} faces".strip())
    ax.legend(loc="upper right", fontsize=8)
    return figure


def episode_3d(trace: EpisodeTrace, inspect_range: float, title: str = "") -> Figure:
    """The episode in 3D: obstacles, path, and every target face coloured by its state."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: PLC0415 - 3D only here

    room, track = trace.room, trace.track
    states = face_states(trace.face_distances, inspect_range)
    figure = new_figure(8, 7)
    ax = figure.add_subplot(projection="3d")
    corners = room.vertices[room.triangles]
    on_target = room.face_of_triangle >= 0
    obstacle = ~on_target & ~_shell_triangles(room)
    palette = np.array([to_rgba(c) for c in (UNSEEN, FAR, COVERED)])
    ax.add_collection3d(
        Poly3DCollection(corners[obstacle], facecolor="0.6", edgecolor="none", alpha=0.25)
    )
    ax.add_collection3d(
        Poly3DCollection(
            corners[on_target],
            facecolor=palette[states[room.face_of_triangle[on_target]]],
            edgecolor="0.2",
            linewidth=0.2,
        )
    )
    ax.plot(track[:, 0], track[:, 1], track[:, 2], color="tab:blue", linewidth=1.0)
    ax.set(xlim=(0, room.size[0]), ylim=(0, room.size[1]), zlim=(0, room.size[2]))
    ax.set_box_aspect(tuple(room.size))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    for colour, name in zip(
        (COVERED, FAR, UNSEEN), ("covered", "seen too far", "unseen"), strict=True
    ):
        ax.plot([], [], marker="s", color=colour, linestyle="", label=name)
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title(title)
    return figure


def _shell_triangles(room: Room) -> NDArray[np.bool_]:
    """Triangles of the room's walls, floor and ceiling: all three corners on one bounding plane."""
    corners = room.vertices[room.triangles]
    on_low = np.all(np.abs(corners) < 1e-9, axis=1)
    on_high = np.all(np.abs(corners - room.size) < 1e-9, axis=1)
    return (on_low | on_high).any(axis=1)


def coverage_figure(results: Mapping[str, EvaluationResult]) -> Figure:
    """Strict coverage % (of the feasible faces) against time, a panel per obstacle count, a
    line per controller; dotted: 95 % and 100 % of the feasible (as 004 Fig 5)."""
    counts = sorted({r.obstacles for result in results.values() for r in result.results})
    columns = min(len(counts), 3)
    rows = math.ceil(len(counts) / columns)
    figure = new_figure(4.2 * columns, 3.4 * rows)
    for index, obstacles in enumerate(counts):
        ax = figure.add_subplot(rows, columns, index + 1)
        for name, result in results.items():
            rows_k = [r for r in result.results if r.obstacles == obstacles]
            if not rows_k:
                continue
            row = rows_k[0]
            (line,) = ax.plot(row.curve_times, row.curve_mean, label=name)
            ax.fill_between(
                row.curve_times, row.curve_p5, row.curve_p95, color=line.get_color(), alpha=0.15
            )
        for level in (95.0, 100.0):
            ax.axhline(level, color="0.5", linestyle=":", linewidth=0.8, label="_feasible")
        ax.set_title(f"{obstacles} obstacles", fontsize=10)
        ax.set_ylim(0, 101)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("strict coverage [% of feasible]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="lower right")
    figure.tight_layout()
    return figure


def episode_coverage_figure(trace: EpisodeTrace, control_hz: float, title: str = "") -> Figure:
    """Coverage % of one episode against time."""
    figure = new_figure(7, 3.5)
    ax = figure.add_subplot()
    times = np.arange(len(trace.track)) / control_hz
    ax.plot(times, 100.0 * trace.track[:, 4], color="tab:blue")
    ax.set_ylim(0, 100)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("coverage [%]")
    ax.grid(alpha=0.3)
    ax.set_title(title)
    figure.tight_layout()
    return figure


def write_episode_pictures(
    trace: EpisodeTrace,
    config: EnvConfig,
    out: str | os.PathLike[str],
    *,
    prefix: str = "episode",
    title: str = "",
) -> list[Path]:
    """``<prefix>_top.png``, ``<prefix>_3d.png`` and ``<prefix>_coverage.png`` in ``out``."""
    root, inspect_range, control_hz = Path(out), config.inspect_range, config.control_hz
    return [
        save_figure(episode_top_down(trace, inspect_range, title), root / f"{prefix}_top.png"),
        save_figure(episode_3d(trace, inspect_range, title), root / f"{prefix}_3d.png"),
        save_figure(
            episode_coverage_figure(trace, control_hz, title), root / f"{prefix}_coverage.png"
        ),
    ]


def training_figure(progress: Mapping[str, str | os.PathLike[str]], window: int = 10) -> Figure:
    """Coverage and crashes of the episodes ending during training, per run's ``progress.csv``.

    Each point pools the episodes of ``window`` consecutive updates (weighted by their count);
    the dotted lines mark where the curriculum adds obstacles.
    """
    figure = new_figure(10.0, 3.6)
    cover_ax, crash_ax = figure.add_subplot(1, 2, 1), figure.add_subplot(1, 2, 2)
    for name, path in progress.items():
        table = np.genfromtxt(path, delimiter=",", names=True)
        steps, episodes = table["steps"], table["episodes"]
        for ax, column in ((cover_ax, "coverage_pct"), (crash_ax, "crash_pct")):
            x, y = _pooled(steps, episodes, np.nan_to_num(table[column]), window)
            ax.plot(x / 1e3, y, label=name)
    first = np.genfromtxt(next(iter(progress.values())), delimiter=",", names=True)
    changes = np.flatnonzero(np.diff(first["obstacles"]) != 0)
    for ax, label in ((cover_ax, "coverage [%]"), (crash_ax, "crashed episodes [%]")):
        for index in changes:
            ax.axvline(first["steps"][index + 1] / 1e3, color="0.6", linestyle=":")
        ax.set_xlabel("environment steps [thousands]")
        ax.set_ylabel(label)
        ax.set_ylim(0, 100)
        ax.grid(alpha=0.3)
    cover_ax.legend(fontsize=8, loc="lower right")
    figure.tight_layout()
    return figure


def _pooled(
    steps: NDArray, episodes: NDArray, values: NDArray, window: int
) -> tuple[NDArray, NDArray]:
    """Episode-weighted means of ``values`` over consecutive blocks of ``window`` updates."""
    blocks = np.arange(len(steps)) // window
    count = np.bincount(blocks, weights=episodes)
    total = np.bincount(blocks, weights=episodes * values)
    last = np.bincount(blocks, weights=steps) / np.bincount(blocks)
    keep = count > 0
    return last[keep], total[keep] / count[keep]
