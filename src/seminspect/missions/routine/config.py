"""The settings of a routine mission (002), with the camera and view constraints they imply."""

from __future__ import annotations

import math

from pydantic import BaseModel, ConfigDict, Field

from seminspect.planning.view_planner import ViewConstraints
from seminspect.sensors import CameraModel
from seminspect.worlds.routine_sites import DEFAULT_LENGTH


class RoutineConfig(BaseModel):
    """Every setting of a routine mission (defaults: 002 Sec IV where it gives one)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    world: str = "mine-drift"
    scenario: str = "nominal"
    seed: int = Field(0, ge=0)
    length: float = Field(DEFAULT_LENGTH, ge=10, le=200, description="drift length [m]")
    adapt: bool = Field(True, description="Algorithm 1; False tracks the global tour directly")
    d_view: float = Field(2.0, gt=0, description="desired viewing distance [m] (002: 2 m)")
    overlap_h: float = Field(0.6, ge=0, lt=1, description="γ_H (002: 0.6)")
    overlap_v: float = Field(0.6, ge=0, lt=1, description="γ_V (002 gives none; = γ_H)")
    hfov_deg: float = Field(69.5, gt=0, lt=180, description="α (002: 69.5°)")
    vfov_deg: float = Field(45.0, gt=0, lt=180, description="β (002: 45°)")
    gamma_t: float = Field(0.5, gt=0, lt=1, description="Γ_t (002: 0.5)")
    horizon: int = Field(3, ge=1, le=20, description="prediction horizon N (poses)")
    map_resolution: float = Field(0.1, ge=0.05, le=0.5)
    robot_radius: float = Field(0.3, gt=0)
    speed: float = Field(0.5, gt=0, description="speed limit [m/s]")
    z_limits: tuple[float, float] = (0.5, 4.0)
    segment_m: float = Field(3.0, gt=0, description="navigation segment length [m]")
    image_stride: int = Field(2, ge=1, le=8, description="render every n-th pixel for measures")

    def view_constraints(self) -> ViewConstraints:
        return ViewConstraints(
            d_view=self.d_view,
            overlap_h=self.overlap_h,
            overlap_v=self.overlap_v,
            hfov_deg=self.hfov_deg,
            vfov_deg=self.vfov_deg,
        )

    def camera(self) -> CameraModel:
        """A 640-pixel-wide camera whose height gives the vertical field of view β."""
        fx = 320.0 / math.tan(math.radians(self.hfov_deg) / 2)
        height = 2 * round(fx * math.tan(math.radians(self.vfov_deg) / 2))
        return CameraModel(640, height, self.hfov_deg, 30.0)
