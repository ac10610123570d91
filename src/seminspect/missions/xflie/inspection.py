"""``π^insp``: inspecting one target level by level (000 Sec V-B, eqs 7-10).

``Level-0`` starts where the robot arrived (eq 7). At every view the pose is registered with
its image (eq 9) and the part detections on the target go to the interim Pose-Feature graph;
the surface tracker gives the next view (002 eqs 1-2) until :class:`LevelCompletion` ends the
level (eq 8). Each level is then pruned (eq 10). Aerial robots climb one vertical step while the
target rises above the view or above the robot itself (a roof is seen only from above it);
ground robots do one level.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
from numpy.typing import NDArray

from seminspect.core.params import InspectionParams
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import TargetNode
from seminspect.missions.xflie.completion import LevelCompletion, LevelState
from seminspect.missions.xflie.context import MissionContext
from seminspect.missions.xflie.sightings import target_view
from seminspect.missions.xflie.surface import SurfaceTracker
from seminspect.perception.detections import observe
from seminspect.planning.view_planner import ViewConstraints
from seminspect.sensors import Frame

#: A part belongs to the inspected target when this share of its mask lies on the target's.
PART_OVERLAP = 0.5
#: Pixels a target's mask is grown by before parts are tested against it.
MASK_GROWTH_PX = 5
#: An inspection with fewer views than this in its first level is cancelled.
MIN_VIEWS = 3
#: Aerial robots fly their last level at least this far above the target's observed top, so
#: that its roof is in view as well as its walls [m].
ROOF_CLEARANCE_M = 0.5


class LevelInspection:
    """Inspects a target level by level and leaves it in the graph, or cancels it.

    Args:
        ctx: the mission's shared state.
        view: the view planner's constraints.
        camera_pitch: the camera's tilt below the horizon [rad].
    """

    def __init__(self, ctx: MissionContext, view: ViewConstraints, camera_pitch: float) -> None:
        self.ctx = ctx
        self.view = view
        self.camera_pitch = camera_pitch
        self.tracker = SurfaceTracker(ctx, view)
        self.completion = LevelCompletion(ctx)
        #: Per level of the current target: whether eq (8) (or the cap) closed it.
        self.closed_levels: list[bool] = []

    def inspect(self, target: TargetNode) -> bool:
        """Every level of ``target``; True when it is inspected, False when cancelled."""
        ctx = self.ctx
        start = ctx.view_pose(image=None)
        self.tracker.start_target()
        self.closed_levels = []
        with ctx.timers("graph"):
            ctx.graph.begin_inspection(target.id, start)
        heights: list[float] = []
        for level in range(ctx.config.inspection.max_levels):
            if level > 0 and not self.climb(target, heights):
                break
            self.closed_levels.append(self.inspect_level(target, heights))
            self.close_level()
            if ctx.config.mode != "aerial" or ctx.time_left <= 0:
                break
        if len(LayeredSemanticGraph.entry_level(target).poses) < MIN_VIEWS:
            with ctx.timers("graph"):
                ctx.graph.cancel_inspection()
            ctx.unreachable.add(target.id)
            ctx.event("inspection-cancelled", target=target.id, reason="too few views")
            return False
        closed = [i for i, done in enumerate(self.closed_levels) if done]
        # Aerial robots circle structures much larger than the camera's footprint, each level
        # perhaps in part: their polygon grows with every level.
        with ctx.timers("graph"):
            ctx.graph.finish_inspection(
                polygon_level=closed[0] if closed else 0, every_level=ctx.config.mode == "aerial"
            )
        for pruned in ctx.graph.pruned:
            ctx.event("discarded", target=pruned, reason=f"re-detection of {target.id}")
        return True

    def inspect_level(self, target: TargetNode, heights: list[float]) -> bool:
        """One level; True when it ended by eq (8) or the cap, False when the robot was stuck
        or the time ran out. ``heights`` collects the top of the target in every view."""
        ctx, tracker = self.ctx, self.tracker
        state = LevelState(ctx.platform.position.copy())
        surface = np.empty((0, 3))
        while ctx.time_left > 0:
            frame = ctx.capture(intensity=True)
            mask, points = target_view(ctx, frame, target)
            if len(points):
                heights.append(float(points[:, 2].max()))
                tracker.target_cloud.add(points)
            visible = tracker.surface(points)
            if len(visible):  # out of sight for a moment (a corner): keep the last surface
                surface = visible
            self.register_view(target, frame, mask, points)
            state.poses += 1
            seen = tracker.target_cloud.points
            centre = seen.mean(axis=0) if len(seen) else target.position
            if self.completion.is_complete(state, frame, target.id, centre):
                return True
            if not tracker.step_along(surface, target):
                break
        return False

    def register_view(
        self,
        target: TargetNode,
        frame: Frame,
        mask: NDArray[np.bool_] | None,
        points: NDArray[np.float64],
    ) -> None:
        """Eq (9) for the view, and its features into the interim ``G~^PF``."""
        ctx = self.ctx
        image = None
        if ctx.run is not None and ctx.config.inspection.save_images:
            image = ctx.run.write_image(f"{target.id}-{ctx.frames_seen:05d}", frame.grey())
        with ctx.timers("graph"):
            ctx.graph.register_pose(ctx.view_pose(image))
        ctx.recorder.coverage.add_frame(target.id, frame, points)
        if mask is None:
            return
        grown = dilate(mask, MASK_GROWTH_PX)
        with ctx.timers("perception"):
            parts = ctx.detect(frame, "part", ctx.config.feature_labels)
            features = [
                observe(frame, p, image=image, method="median")
                for p in parts
                if np.count_nonzero(p.mask & grown) >= PART_OVERLAP * p.area_px
            ]
        with ctx.timers("graph"):
            for z in features:
                if z is not None:
                    ctx.graph.register_feature(z)

    def climb(self, target: TargetNode, heights: list[float]) -> bool:
        """Start the next level one vertical step up, while the target rises above the view
        or the robot has not yet risen ``ROOF_CLEARANCE_M`` above the target's top."""
        ctx = self.ctx
        top = max(heights) if heights else target.position[2]
        half = math.radians(self.view.vfov_deg) / 2
        reach = self.view.d_view * math.tan(half - self.camera_pitch)
        altitude = ctx.platform.position[2]
        if altitude + reach >= top and altitude >= top + ROOF_CLEARANCE_M:
            return False
        here = ctx.platform.position
        goal = here + np.array([0.0, 0.0, self.view.vertical_step])
        if not ctx.navigator.segment_is_free(here, goal):
            ctx.event("climb-blocked", target=target.id, height=round(float(goal[2]), 2))
            return False
        with ctx.timers("driving"):
            motion = ctx.platform.move_to(goal, ctx.platform.yaw)
        ctx.navigator.sense_lidar()
        if not motion.reached:
            return False
        with ctx.timers("graph"):
            ctx.graph.begin_level(ctx.view_pose(image=None), via=self.climb_route(here))
        ctx.event("level", target=target.id, height=round(float(goal[2]), 2))
        return True

    def close_level(self) -> None:
        """Eq (10) for the level just inspected. Its ring edge (last pose back to the level's
        start) is a straight segment the robot never drove, so it is added only where the
        robot's map shows that segment free (known space, the planners' clearance)."""
        ctx = self.ctx
        level = ctx.graph.current_level
        assert level is not None, "a level is open while a target is inspected"
        poses = level.poses
        ring = len(poses) > 1 and ctx.navigator.segment_is_free(
            poses[-1].position, level.position, known_only=True
        )
        with ctx.timers("graph"):
            ctx.graph.close_level(close_ring=ring)
        if len(poses) > 1 and not ring:
            ctx.event("ring-left-open", level=level.id)

    def climb_route(self, climb_start: NDArray[np.float64]) -> NDArray[np.float64]:
        """How the robot got from the closing level's start to where it climbed: through the
        ring edge when the level kept it, otherwise along its view poses as it drove them."""
        graph = self.ctx.graph
        level = graph.current_level
        assert level is not None, "a level is open while a target is inspected"
        poses = level.poses
        ring = len(poses) > 1 and graph.edge(poses[-1].id, level.id) is not None
        chain = [p.position for p in (poses[-1:] if ring else poses)]
        if not chain or np.linalg.norm(chain[-1] - climb_start) > 1e-9:
            chain.append(climb_start)
        return np.array(chain)


def dilate(mask: NDArray[np.bool_], pixels: int) -> NDArray[np.bool_]:
    """Grow a mask by ``pixels`` 4-connected steps (a diamond around each pixel).

    OpenCV's dilation by the 3 x 3 cross, which beyond the image's edge sees nothing to grow
    from: scipy's ``binary_dilation`` with its defaults, at a tenth of the cost on a frame
    (``pixels=0`` leaves the mask as it is, where scipy would grow it until nothing changes).
    """
    if pixels <= 0:
        return mask.copy()
    cross = cv2.getStructuringElement(cv2.MORPH_CROSS, (3, 3))
    return cv2.dilate(mask.astype(np.uint8), cross, iterations=pixels).astype(bool)


def platform_vfov(params: InspectionParams) -> float:
    """Vertical field of view of a ``I_w x I_h`` camera with horizontal FOV ``α``."""
    half = math.atan(math.tan(params.fov_rad / 2) * params.image_height / params.image_width)
    return math.degrees(2 * half)
