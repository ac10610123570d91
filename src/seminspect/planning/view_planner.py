"""The reactive local view planner of FLIE, 002 eqs (1)-(2).

From the robot's position ``X`` and the surface points it currently sees, the nearest surface
point ``p_nn`` fixes a viewing frame:

* ``ν_x = (p_nn - X) / ||p_nn - X||`` points at the surface,
* ``ν_y = ν_up x ν_x`` runs along it, ``ν_z = ν_x x ν_y`` up it,

and the next view pose is

    X_ref = X + ν_x d_insp + ν_y d_hov + ν_z d_vov                                   (1)
    ψ_ref = atan2(ν_x[1], ν_x[0])  (seen from X_ref)                                   (2)

with the horizontal and vertical steps that leave the overlaps ``γ_H``, ``γ_V`` between
consecutive images of a camera with fields of view ``α``, ``β`` at distance ``d = ||p_nn - X||``:

    d_hov = 2 tan(α/2) d (1 - γ_H),    d_vov = 2 tan(β/2) d (1 - γ_V).

Readings of the text, documented because the paper leaves them implicit:

* ``d_insp`` is the correction that restores the viewing distance, ``d - d_view`` (positive when
  too far from the surface), so the robot keeps ``d_view`` from the surface while it steps along.
* Within a level the viewing frame is horizontal (``ν_x`` has its vertical part removed): a
  level is flown or walked at a constant height, and heights change only by a level step,
  ``d_vov`` along ``+z``, when the planner moves to the next level.
* The horizontal step is taken at the viewing distance ``d_view`` rather than the current
  distance, so the image overlap holds for the images the robot takes at ``d_view``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field

from seminspect.core.errors import PlanningError
from seminspect.geometry.transforms import as_point, as_points

UP = np.array([0.0, 0.0, 1.0])


class ViewConstraints(BaseModel):
    """Viewing constraints of 002 Sec III-A (defaults: 002 Sec IV and 000 Table 1)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    d_view: float = Field(2.0, gt=0, description="desired viewing distance [m] (002: 2 m)")
    overlap_h: float = Field(0.6, ge=0, lt=1, description="γ_H horizontal image overlap (002: 0.6)")
    overlap_v: float = Field(0.6, ge=0, lt=1, description="γ_V vertical image overlap")
    hfov_deg: float = Field(69.4, gt=0, lt=180, description="α horizontal field of view [deg]")
    vfov_deg: float = Field(
        54.9, gt=0, lt=180, description="β vertical field of view [deg] (640x480 at α=69.4)"
    )
    #: +1 steps to the robot's left along the surface (clockwise around an object seen from
    #: above), -1 to its right.
    direction: Literal[-1, 1] = Field(1, description="+1 or -1: side to step along the surface")

    @property
    def horizontal_step(self) -> float:
        """``d_hov`` at the viewing distance."""
        return 2.0 * math.tan(math.radians(self.hfov_deg) / 2) * self.d_view * (1 - self.overlap_h)

    @property
    def vertical_step(self) -> float:
        """``d_vov`` at the viewing distance: the height between inspection levels."""
        return 2.0 * math.tan(math.radians(self.vfov_deg) / 2) * self.d_view * (1 - self.overlap_v)


@dataclass(frozen=True, slots=True)
class ViewPose:
    """A reference view pose ``X_ref = [x, y, z, ψ]`` and the surface point that set it."""

    position: NDArray[np.float64]
    yaw: float
    nearest: NDArray[np.float64]
    distance: float


def nearest_surface_point(
    position: ArrayLike, surface: ArrayLike
) -> tuple[NDArray[np.float64], float]:
    """``p_nn``: the surface point nearest to ``position`` in the horizontal plane."""
    here = as_point(position, "robot position")
    points = as_points(surface, "surface points")
    d2 = ((points[:, :2] - here[:2]) ** 2).sum(axis=1)
    i = int(np.argmin(d2))
    return points[i], math.sqrt(float(d2[i]))


def viewing_frame(
    position: NDArray[np.float64], nearest: NDArray[np.float64]
) -> tuple[np.ndarray, ...]:
    """Unit vectors ``ν_x, ν_y, ν_z`` of eq (1), with ``ν_x`` kept horizontal."""
    towards = nearest - position
    towards[2] = 0.0
    norm = float(np.linalg.norm(towards))
    if norm < 1e-9:
        raise PlanningError("the robot is on the surface point; no viewing direction")
    nu_x = towards / norm
    nu_y = np.cross(UP, nu_x)
    nu_z = np.cross(nu_x, nu_y)
    return nu_x, nu_y, nu_z


def next_view_pose(
    position: ArrayLike,
    surface: ArrayLike,
    constraints: ViewConstraints,
    *,
    climb: bool = False,
) -> ViewPose:
    """Eqs (1)-(2): the next view pose along the surface, or one level up when ``climb``."""
    here = as_point(position, "robot position")
    points = as_points(surface, "surface points")
    nearest, distance = nearest_surface_point(here, points)
    nu_x, nu_y, nu_z = viewing_frame(here, nearest)
    d_insp = distance - constraints.d_view
    if climb:
        step = nu_x * d_insp + nu_z * constraints.vertical_step
    else:
        step = nu_x * d_insp + nu_y * constraints.direction * constraints.horizontal_step
    target = here + step
    ahead, ahead_distance = nearest_surface_point(target, points)
    if ahead_distance < 1e-9:
        ahead = nearest
    heading = ahead - target
    yaw = math.atan2(heading[1], heading[0])  # eq (2), seen from the new pose
    return ViewPose(target, yaw, nearest, distance)
