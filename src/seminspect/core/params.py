"""The inspection parameters of 000 Tables 1 and 2, as typed, validated presets.

One :class:`InspectionParams` object carries every symbol of the tables. The scene graph reads
its uniqueness radii, the planner its arrival radius and image size, the mission its
scene-similarity settings; all of them read the same object so a run is described by one config.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from seminspect.core.names import unknown_name
from seminspect.core.validation import build

PresetName = Literal["urban-simulated", "urban-experimental", "collapsed-buildings"]


class InspectionParams(BaseModel):
    """Symbols of 000 Tables 1-2 (names follow the paper; units in the field descriptions)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    fov_deg: float = Field(69.4, gt=0, lt=180, description="α: horizontal field of view [deg]")
    d_max: float = Field(30.0, gt=0, description="maximum reliable sensor range [m]")
    image_width: int = Field(640, gt=0, description="I_w: image width [px]")
    image_height: int = Field(480, gt=0, description="I_h: image height [px]")
    d_thresh_I: float = Field(
        5.0, gt=0, description="d_thresh^I: radius around a level's start for similarity [m]"
    )
    d_check_T: float = Field(4.0, gt=0, description="d_check^T: target uniqueness radius [m]")
    d_check_F: float = Field(1.5, gt=0, description="d_check^F: feature uniqueness radius [m]")
    gamma_thresh: float = Field(
        0.3, ge=0, description="Γ_thresh: scene-similarity score that ends a level"
    )
    horizon_N: int = Field(3, ge=1, description="N: candidate images matched for similarity")
    epsilon: float = Field(2.0, gt=0, description="ε: arrival radius around a target node [m]")
    utility_S_p: float = Field(50.0, ge=0, description="S_p: proximity weight, eq (6)")
    utility_S_a: float = Field(5.0, ge=0, description="S_a: mask-area weight, eq (6)")
    utility_S_n: float = Field(5.0, ge=0, description="S_n: centrality weight, eq (6)")

    @model_validator(mode="after")
    def _finite(self) -> InspectionParams:
        for name, value in self:
            if isinstance(value, float) and not math.isfinite(value):
                raise ValueError(f"{name} must be finite")
        return self

    @property
    def fov_rad(self) -> float:
        return math.radians(self.fov_deg)

    @property
    def image_area(self) -> int:
        return self.image_width * self.image_height

    def with_overrides(self, **changes: float | int) -> InspectionParams:
        """A validated copy with some fields changed (raises :class:`InvalidInputError`)."""
        return make_params(self.model_dump() | changes)


def make_params(values: Mapping[str, float | int]) -> InspectionParams:
    """Validate raw values into :class:`InspectionParams`, with one readable error line."""
    return build(InspectionParams, values, "inspection parameter")


#: 000 Table 1 (urban, simulated and experimental) and Table 2 (collapsed buildings).
PRESETS: dict[str, InspectionParams] = {
    "urban-simulated": InspectionParams(),
    "urban-experimental": InspectionParams(fov_deg=86.0),
    "collapsed-buildings": InspectionParams(d_check_T=8.0, gamma_thresh=0.4, epsilon=5.0),
}


def preset(name: str) -> InspectionParams:
    """Look up a named preset; unknown names list the valid ones."""
    try:
        return PRESETS[name]
    except KeyError:
        raise unknown_name("preset", name, PRESETS) from None
