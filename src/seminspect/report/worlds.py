"""Pictures of worlds: a labelled top-down map and a 3D view.

Both draw the world's triangles coloured by class. The top-down map paints faces from low to high
so roofs cover walls, and writes each object's name at its centroid. The 3D view culls faces
that point away from the viewer, so the inside of a tunnel shows through its roof.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Literal, cast

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator
from mpl_toolkits.mplot3d import Axes3D
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.core.io import atomic_write_with
from seminspect.core.rng import stream_key
from seminspect.worlds import GROUND, World

View = Literal["top", "3d", "both"]

CLASS_COLOURS: dict[str, str] = {
    "ground": "#e6e6e0",
    "background": "#9a9a9a",
    "building": "#c8b08a",
    "wall": "#8c8c8c",
    "car": "#3b6fb6",
    "truck": "#e08a2c",
    "rock-face": "#8b5a2b",
    "rock": "#5c4033",
    "target": "#d62728",
    "obstacle": "#7f8fa6",
    "sidewalk": "#cfc8bc",
    "grass": "#9cc987",
    "asphalt": "#5f6268",
    "tree": "#2e7d32",
}
#: Faces drawn in the 3D view at most; larger worlds are subsampled evenly.
MAX_3D_FACES = 25_000


def class_colour(name: str) -> str:
    """Fixed colour of a class; unknown classes get a stable colour from their name."""
    if name in CLASS_COLOURS:
        return CLASS_COLOURS[name]
    cmap = matplotlib.colormaps["tab20"]
    return matplotlib.colors.to_hex(cmap(stream_key(name) % 20))


def _face_colours(world: World, shade: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
    palette = np.array([matplotlib.colors.to_rgb(class_colour(c)) for c in world.class_names])
    colours = palette[world.face_class]
    if shade is not None:
        colours = colours * shade[:, None]
    return np.clip(colours, 0.0, 1.0)


def draw_top_down(world: World, ax: Axes) -> None:
    """Faces seen from above, object names at their centroids, and the start pose."""
    tris = world.triangles
    order = np.argsort(tris[:, :, 2].max(axis=1), kind="stable")
    up = world.face_normals[:, 2] > 1e-3  # walls have no area from above, ceilings face down
    keep = order[up[order]]
    colours = _face_colours(world)[keep]
    ax.add_collection(
        PolyCollection(
            list(tris[keep, :, :2]), facecolors=colours, edgecolors=colours, linewidths=0.2
        )
    )
    for info in world.instances.values():
        if info.class_name != "building" or len(world.instances) < 40:
            ax.annotate(info.name, tuple(info.centroid[:2]), fontsize=6, ha="center", va="center")
    if world.metadata.get("drive_path"):
        path = np.asarray(world.metadata["drive_path"], dtype=np.float64)
        ax.plot(path[:, 0], path[:, 1], "--", color="crimson", linewidth=0.8, label="drive path")
    sx, sy = world.start_position[:2]
    ax.plot([sx], [sy], marker="*", color="crimson", markersize=10, label="start")
    ax.arrow(sx, sy, 2 * np.cos(world.start_yaw), 2 * np.sin(world.start_yaw), color="crimson")
    lo, hi = world.bounds
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(loc="upper right", fontsize=7)


def draw_3d(world: World, ax: Axes3D, elevation: float = 35.0, azimuth: float = -60.0) -> None:
    """Faces seen from (elevation, azimuth) degrees, back faces culled, Lambert-shaded."""
    el, az = np.radians(elevation), np.radians(azimuth)
    towards_viewer = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    facing = world.face_normals @ towards_viewer
    ground = world.class_names.index(GROUND) if GROUND in world.class_names else -1
    keep = np.flatnonzero((facing > 0) & (world.face_class != ground))
    if len(keep) > MAX_3D_FACES:
        keep = keep[np.linspace(0, len(keep) - 1, MAX_3D_FACES).astype(int)]
    colours = _face_colours(world, 0.45 + 0.55 * facing.clip(0.0, 1.0))[keep]
    ax.add_collection3d(
        Poly3DCollection(
            world.triangles[keep], facecolors=colours, edgecolors=colours, linewidths=0.2
        )
    )
    lo, hi = world.bounds
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect((hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]))
    ax.zaxis.set_major_locator(MaxNLocator(nbins=3))  # flat worlds leave little room for ticks
    ax.view_init(elev=elevation, azim=azimuth)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")


def world_figure(world: World, view: View = "both") -> Figure:
    """A figure with the top-down map, the 3D view or both side by side."""
    if view not in ("top", "3d", "both"):
        raise InvalidInputError(f"view must be 'top', '3d' or 'both', got {view!r}")
    views = ["top", "3d"] if view == "both" else [view]
    fig = plt.figure(figsize=(8 * len(views), 6.5))
    for i, name in enumerate(views, start=1):
        if name == "top":
            draw_top_down(world, fig.add_subplot(1, len(views), i))
        else:
            draw_3d(world, cast(Axes3D, fig.add_subplot(1, len(views), i, projection="3d")))
    scenario = world.metadata.get("scenario")
    title = f"{world.name}" + (f" ({scenario})" if scenario else "") + f", seed {world.seed}"
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def save_world_picture(world: World, path: str | os.PathLike[str], view: View = "both") -> Path:
    """Draw ``world`` and write a PNG atomically."""
    fig = world_figure(world, view)
    try:
        return atomic_write_with(path, lambda buf: fig.savefig(buf, format="png", dpi=130))
    finally:
        plt.close(fig)
