"""Parameters of the task-driven terrain scene graph (001 Sec III-B), validated and frozen."""

from __future__ import annotations

import math
from collections.abc import Mapping

from pydantic import BaseModel, ConfigDict, Field, model_validator

from seminspect.core.validation import build


class TerrainGraphParams(BaseModel):
    """Everything phase 2 needs besides the prompts and the similarity thresholds.

    Lengths are metres; the grid parameters follow 001 Sec III-B.3, the object parameters
    Sec III-B.2, the region parameters the Clio-style information bottleneck of ``regions``.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    cell_size: float = Field(0.5, gt=0, description="side of a terrain grid cell")
    min_points_per_cell: int = Field(1, ge=1, description="terrain points that make a cell")
    smoothing_cells: int = Field(1, ge=0, description="dilation/erosion radius in cells")
    min_patch_area: float = Field(4.0, ge=0, description="smaller terrain patches are dropped")
    prune_length: float = Field(1.5, ge=0, description="GVD spurs shorter than this are pruned")
    split_deviation: float = Field(
        1.0, gt=0, description="an edge chain deviating more than this gets a node"
    )
    split_length: float = Field(8.0, gt=0, description="nodes farther apart get a midpoint node")
    max_iterations: int = Field(25, ge=0, description="cap on the refinement iterations")
    object_eps: float = Field(0.75, gt=0, description="DBSCAN neighbourhood radius")
    object_min_points: int = Field(15, ge=1, description="DBSCAN min_samples (points)")
    object_voxel: float = Field(0.15, gt=0, description="object points are voxelised first")
    region_top_k: int = Field(2, ge=1, description="tasks kept per primitive (Clio top-k)")
    region_delta: float = Field(
        0.02, ge=0, description="stop merging when one merge loses this share of I(X;Y)"
    )

    @model_validator(mode="after")
    def _consistent(self) -> TerrainGraphParams:
        for name, value in self:
            if isinstance(value, float) and not math.isfinite(value):
                raise ValueError(f"{name} must be finite")
        if self.object_voxel >= self.object_eps:
            raise ValueError("object_voxel must be smaller than object_eps")
        return self


def make_terrain_params(values: Mapping[str, float | int]) -> TerrainGraphParams:
    """Validate raw values, with one readable error line."""
    return build(TerrainGraphParams, values, "terrain graph parameter")
