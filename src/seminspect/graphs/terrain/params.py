"""Parameters of the task-driven terrain scene graph (001 Sec III-B), validated and frozen."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, model_validator

from seminspect.core.validation import build
from seminspect.geometry.nearest import median_spacing


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
    region_max_extent: float = Field(
        120.0, gt=0, description="no region spans more than this (x-y box diagonal)"
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


#: Above this median spacing of the terrain points (metres) the defaults, tuned for ground-robot
#: LiDAR (SemanticKITTI's fused terrain 0.025 m, the tests' grid 0.3 m), leave most 0.5 m cells
#: empty: at Autzen's airborne 0.59 m, 57 % of the cells of the ground's footprint are.
DENSE_SPACING = 0.4
#: A derived cell holds about nine points of a regular pattern of the spacing (three a side);
#: at Autzen 3 x 0.59 m = 1.8 m cells fill 79 % of the footprint, which the closing then closes.
CELLS_PER_SPACING = 3.0
#: Objects: DBSCAN's radius must reach past the nearest neighbours of a surface at the spacing.
EPS_PER_SPACING = 2.5
#: Lengths that guard against digitisation noise keep their size in cells when the cell grows.
_GRID_LENGTHS = ("prune_length", "split_deviation")


@dataclass(frozen=True)
class ParamsChoice:
    """The parameters a build uses, and how the cloud's spacing chose them.

    Attributes:
        params: the parameters to build with.
        spacing: median x-y nearest-neighbour distance of the terrain points, metres (NaN
            when there are fewer than two).
        derived: the values derived from the spacing (empty when the defaults fit the cloud);
            values the caller set are never derived.
    """

    params: TerrainGraphParams
    spacing: float
    derived: dict[str, float] = field(default_factory=dict)

    def describe(self) -> str:
        """One line for the user: the spacing and what it changed."""
        if not math.isfinite(self.spacing):
            return "terrain point spacing: too few terrain points to measure"
        head = f"terrain point spacing {self.spacing:.3g} m"
        if not self.derived:
            return f"{head}: default parameters"
        values = ", ".join(f"{name} {value:g}" for name, value in self.derived.items())
        return f"{head} (sparser than {DENSE_SPACING} m): derived {values}"


def _nice(value: float) -> float:
    """``value`` rounded up to two significant digits (1.776 -> 1.8, 0.317 -> 0.32)."""
    step = 10.0 ** (math.floor(math.log10(value)) - 1)
    return round(math.ceil(value / step - 1e-9) * step, 10)


def _derive(spacing: float, user: TerrainGraphParams, fixed: set[str]) -> dict[str, float]:
    """Values for a cloud sparser than :data:`DENSE_SPACING`, leaving ``fixed`` names alone."""
    defaults = TerrainGraphParams()
    cell = user.cell_size if "cell_size" in fixed else _nice(CELLS_PER_SPACING * spacing)
    scale = cell / defaults.cell_size
    eps = user.object_eps if "object_eps" in fixed else _nice(EPS_PER_SPACING * spacing)
    values = {
        "cell_size": cell,
        "min_patch_area": _nice(defaults.min_patch_area * scale**2),
        **{name: _nice(getattr(defaults, name) * scale) for name in _GRID_LENGTHS},
        "object_eps": max(eps, defaults.object_eps),
    }
    # a third of the radius (the defaults use a fifth): at this density such a voxel holds about
    # one point anyway, and larger voxels shorten DBSCAN's neighbour lists, its cost (1 M points)
    values["object_voxel"] = _nice(max(defaults.object_voxel, values["object_eps"] / 3.0))
    if values["object_voxel"] >= values["object_eps"]:  # the user's eps is below the spacing
        values["object_voxel"] = _nice(values["object_eps"] / 5.0)
    return {
        name: value
        for name, value in values.items()
        if name not in fixed and value != getattr(defaults, name)
    }


def params_for_cloud(
    terrain_points: NDArray[np.floating],
    params: TerrainGraphParams | Mapping[str, float | int] | None = None,
    *,
    seed: int = 0,
) -> ParamsChoice:
    """Parameters fitted to the density of a cloud's terrain points.

    ``params`` holds what the user chose: a mapping of names, or a :class:`TerrainGraphParams`
    whose explicitly set fields count as chosen (``make_terrain_params`` sets only the given
    ones). Chosen values always win. The rest keep their defaults unless the terrain's median
    spacing exceeds :data:`DENSE_SPACING`; then the grid is three spacings a cell, the lengths
    measured in cells keep their size in cells and DBSCAN's radius and voxel follow the spacing.
    """
    user = params if isinstance(params, TerrainGraphParams) else make_terrain_params(params or {})
    spacing = median_spacing(terrain_points, planar=True, seed=seed)
    if not (math.isfinite(spacing) and spacing > DENSE_SPACING):
        return ParamsChoice(user, spacing)
    fixed = set(user.model_fields_set)
    derived = _derive(spacing, user, fixed)
    chosen = make_terrain_params({**user.model_dump(include=fixed), **derived})
    return ParamsChoice(chosen, spacing, derived)
