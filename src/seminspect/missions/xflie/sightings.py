"""Seeing targets in a frame: registering every detection (eqs 3-5), and finding one target.

Shared by every phase: exploration registers what each survey frame shows, the approach
confirms the target it came for, and level inspection follows the target's surface.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from seminspect.graphs.lsg.model import TargetNode
from seminspect.missions.xflie.context import MissionContext
from seminspect.perception.detections import detection_points, observe
from seminspect.sensors import Detection, Frame


def register_targets(ctx: MissionContext, frame: Frame) -> list[tuple[Detection, str]]:
    """Eqs (3)-(5) for one frame: register its detections, optimise, merge.

    Returns each detection that became, or merged into, a target node, with that node's id.
    """
    config, graph = ctx.config, ctx.graph
    with ctx.timers("perception"):
        detections = ctx.detect(frame, "instance", config.target_classes)
        observations = [
            observe(
                frame,
                d,
                method=config.localisation,
                erosion_px=config.mask_erosion_px,
                min_height=ctx.min_height,
                max_range=ctx.params.d_max,
            )
            for d in detections
        ]
    with ctx.timers("graph"):
        registered = [d for d, z in zip(detections, observations, strict=True) if z is not None]
        for z in observations:
            if z is not None:
                graph.register_target(z)
        graph.update_robot(frame.odometry_position, frame.odometry_orientation, frame.stamp)
        update = graph.optimise_targets()
    for added in update.added:
        ctx.event(
            "detected",
            target=added,
            position=graph.target(added).position.round(2).tolist(),
        )
    # Candidates are resolved in registration order (one per registered detection).
    return [(d, node) for d, node in zip(registered, update.resolved, strict=True) if node]


def target_view(
    ctx: MissionContext, frame: Frame, target: TargetNode, gate: float | None = None
) -> tuple[NDArray[np.bool_] | None, NDArray[np.float64]]:
    """The mask and points of the target in this frame: the nearest detection of its label
    whose points lie within ``gate`` (default ``2 d_check^T``) of the target."""
    gate = 2.0 * ctx.params.d_check_T if gate is None else gate
    with ctx.timers("perception"):
        detections = ctx.detect(frame, "instance", [target.label])
        best: tuple[float, Detection, NDArray[np.float64]] | None = None
        for detection in detections:
            points = detection_points(frame, detection, ctx.config.mask_erosion_px, ctx.min_height)
            if not len(points):
                continue
            distance = float(np.linalg.norm(np.median(points, axis=0)[:2] - target.position[:2]))
            if distance <= gate and (best is None or distance < best[0]):
                best = (distance, detection, points)
    if best is None:
        return None, np.empty((0, 3))
    return best[1].mask, best[2]
