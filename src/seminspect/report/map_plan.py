"""The picture of ``seminspect plan``: a path on a map file, from above."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from seminspect.mapping.voxel import OCCUPIED, VoxelMap
from seminspect.planning.map_plan import MapPlan
from seminspect.report.figures import new_figure


def map_plan_figure(voxel_map: VoxelMap, plan: MapPlan) -> Figure:
    """Occupied cells at the path's heights in grey (floor and ceiling left out), the path in
    green, start and goal marked."""
    lo, hi = voxel_map.origin, voxel_map.upper
    figure = new_figure(10, 10 * (hi[1] - lo[1]) / max(hi[0] - lo[0], 1e-9) + 1.0)
    ax = figure.add_subplot()
    points = plan.path.waypoints
    heights = lo[2] + (np.arange(voxel_map.shape[2]) + 0.5) * voxel_map.resolution
    band = (heights >= points[:, 2].min() - 0.25) & (heights <= points[:, 2].max() + 0.25)
    walls = (voxel_map.states[:, :, band] == OCCUPIED).any(axis=2).T
    ax.imshow(walls, origin="lower", extent=(lo[0], hi[0], lo[1], hi[1]), cmap="Greys", alpha=0.5)
    ax.plot(points[:, 0], points[:, 1], color="tab:green", linewidth=1.5, label="path")
    for snap, marker, name in ((plan.start, "o", "start"), (plan.goal, "*", "goal")):
        ax.scatter(snap.point[0], snap.point[1], marker=marker, s=60, zorder=3, label=name)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"{plan.path.length:.1f} m path, {plan.clearance_m:g} m clear")
    ax.legend(fontsize=7, loc="upper left")
    return figure
