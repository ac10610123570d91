"""Pictures of a routine run, drawn from its run directory alone.

* ``performance.png``: viewpoint utility, viewing distance against ``d_view``, ``Γ_s`` against
  ``Γ_t`` and the RMSE of ``Π_GVP`` and Kabsch-aligned ``Π̂_GVP`` to ``Π_LVP`` over time: the
  panels of 002 Figs 8, 9 and 11;
* ``changes.png``: the change report, top down: ``M_H``'s occupied cells, the cells that turned
  occupied (added) or free (removed) in ``M_C``, the regions, their views and the path;
* :func:`comparison_figure`: two runs' performance panels overlaid (adaptive vs baseline).
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from seminspect.core.io import read_versioned_json
from seminspect.mapping.voxel import OCCUPIED, VoxelMap, load_map
from seminspect.missions.routine.measures import change_masks
from seminspect.missions.routine.run import PRIOR_FILE, TOUR_FORMAT
from seminspect.report.figures import new_figure, save_figure
from seminspect.runs.directory import read_run_config
from seminspect.runs.trajectory import load_trajectory

#: Heights drawn as M_H's walls in the change picture [m].
WALL_BAND_M = (0.3, 4.0)

PANELS = (
    ("utility", "viewpoint utility"),
    ("view_distance_m", "viewing distance [m]"),
    ("gamma_s", "Γ_s"),
    ("rmse", "RMSE [m]"),
)


def load_views(run_dir: Path) -> dict[str, np.ndarray]:
    """``views.csv`` as float columns (task names dropped); empty when absent."""
    path = run_dir / "views.csv"
    if not path.exists():
        return {}
    with path.open(encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    if not rows:
        return {}
    return {key: np.array([float(row[key]) for row in rows]) for key in rows[0] if key != "task"}


def _panels(figure: Figure) -> list:
    return [figure.add_subplot(len(PANELS), 1, i + 1) for i in range(len(PANELS))]


def draw_performance(
    axes: list, views: dict[str, np.ndarray], config: dict, label: str = ""
) -> None:
    """Fill the four panels with one run's time series."""
    if not views:
        return
    t = views["t"]
    suffix = f" ({label})" if label else ""
    axes[0].plot(t, views["utility"], marker=".", label=f"utility{suffix}")
    axes[1].plot(t, views["view_distance_m"], marker=".", label=f"distance{suffix}")
    axes[2].plot(t, views["gamma_s"], marker=".", label=f"Γ_s{suffix}")
    axes[3].plot(t, views["rmse_before_m"], marker=".", label=f"before Kabsch{suffix}")
    axes[3].plot(t, views["rmse_after_m"], marker=".", linestyle="--", label=f"after{suffix}")
    axes[1].axhline(config["d_view"], color="grey", linestyle=":", label="d_view")
    axes[2].axhline(config["gamma_t"], color="grey", linestyle=":", label="Γ_t")


def _finish(axes: list) -> None:
    for ax, (_, title) in zip(axes, PANELS, strict=True):
        ax.set_ylabel(title)
        ax.grid(alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7, loc="best")
    axes[-1].set_xlabel("time [s]")


def performance_figure(run_dir: Path) -> Figure:
    config = read_run_config(run_dir)
    figure = new_figure(8, 9)
    axes = _panels(figure)
    draw_performance(axes, load_views(run_dir), config)
    mode = "adaptive" if config.get("adapt", True) else "non-adaptive"
    axes[0].set_title(f"{config['scenario']} seed {config['seed']}: {mode} inspection")
    _finish(axes)
    return figure


def comparison_figure(runs: dict[str, Path]) -> Figure:
    """The performance panels of several runs on one set of axes."""
    figure = new_figure(8, 9)
    axes = _panels(figure)
    for label, run_dir in runs.items():
        draw_performance(axes, load_views(run_dir), read_run_config(run_dir), label)
    axes[0].set_title(" vs ".join(runs))
    _finish(axes)
    return figure


def change_maps(run_dir: Path) -> tuple[VoxelMap, VoxelMap] | None:
    """``(M_H, M_C)`` of a run, or None without both on one grid (e.g. a prior given by another
    file whose grid differs from M_C's). A prior given as a ``.npz`` is read where it was given;
    one of another format (.bt, .ply, .pcd) is read as the run saved it, on its own grid."""
    prior_path = run_dir / PRIOR_FILE
    given = read_run_config(run_dir).get("prior")
    if given and Path(given).suffix.lower() == ".npz":
        prior_path = Path(given)
    current_path = run_dir / "map.npz"
    if not (prior_path.suffix == ".npz" and prior_path.exists() and current_path.exists()):
        return None
    prior, current = load_map(prior_path), load_map(current_path)
    if prior.states.shape != current.states.shape:
        return None
    return prior, current


def wall_band(voxels: VoxelMap) -> NDArray[np.bool_]:
    """The map's z layers drawn as walls from above: no floor, no roof."""
    heights = voxels.origin[2] + (np.arange(voxels.shape[2]) + 0.5) * voxels.resolution
    return (heights > WALL_BAND_M[0]) & (heights < WALL_BAND_M[1])


def wall_columns(voxels: VoxelMap) -> NDArray[np.bool_]:
    """``(ny, nx)``, image order: the columns holding an occupied cell within the wall band."""
    return (voxels.states[:, :, wall_band(voxels)] == OCCUPIED).any(axis=2).T


def change_centres(prior: VoxelMap, current: VoxelMap) -> dict[str, NDArray[np.float64]]:
    """Centres (at z of the grid's first layer) of the columns whose wall-band cells turned
    occupied (``added``) or free (``removed``) in M_C."""
    added, removed = change_masks(prior, current)
    band = wall_band(prior)
    centres = {}
    for name, mask in (("added", added), ("removed", removed)):
        columns = np.argwhere(mask[:, :, band].any(axis=2))
        centres[name] = prior.index_to_world(np.column_stack([columns, np.zeros(len(columns))]))
    return centres


def changes_figure(run_dir: Path) -> Figure | None:
    """Top-down change report; None without both maps (:func:`change_maps`)."""
    maps = change_maps(run_dir)
    if maps is None:
        return None
    prior, current = maps
    figure = new_figure(11, 4)
    ax = figure.add_subplot()
    extent = (prior.origin[0], prior.upper[0], prior.origin[1], prior.upper[1])
    walls = wall_columns(prior)
    ax.imshow(walls, origin="lower", extent=extent, cmap="Greys", alpha=0.35, aspect="equal")
    changes = change_centres(prior, current)
    for colour, name in (("tab:red", "added"), ("tab:blue", "removed")):
        centres = changes[name]
        ax.scatter(centres[:, 0], centres[:, 1], s=4, color=colour, label=f"{name} in M_C")
    _draw_tours(ax, run_dir)
    trajectory = load_trajectory(run_dir)
    if len(trajectory):
        ax.plot(trajectory[:, 1], trajectory[:, 2], color="tab:green", linewidth=1, label="path")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("change report: M_C against M_H (top down)")
    ax.legend(fontsize=7, loc="upper left")
    return figure


def _draw_tours(ax, run_dir: Path) -> None:
    path = run_dir / "tour.json"
    if not path.exists():
        return
    for task in read_versioned_json(path, TOUR_FORMAT, [1])["tasks"]:
        region = np.array(task["region"] + task["region"][:1])
        views = np.array(task["views"]).reshape(-1, 3)
        ax.plot(region[:, 0], region[:, 1], color="black", linewidth=1, linestyle="--")
        ax.scatter(views[:, 0], views[:, 1], s=12, color="tab:orange", zorder=3)
        ax.annotate(task["task"], region[0, :2], fontsize=8)


def render_routine(run_dir: str | Path) -> list[Path]:
    """Draw every picture the run directory has the data for; returns the files written."""
    root = Path(run_dir)
    written = [save_figure(performance_figure(root), root / "performance.png")]
    changes = changes_figure(root)
    if changes is not None:
        written.append(save_figure(changes, root / "changes.png"))
    return written
