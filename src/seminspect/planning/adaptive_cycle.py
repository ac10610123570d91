"""Adaptive local view planning under an outdated map: one cycle of 002 Algorithm 1.

Each cycle takes the next ``N`` poses of the global tour, ``Π_GVP^k``, predicts the local path
``Π_LVP^k`` from the surface the robot measures now, compares the two and picks what to track:

* **Prediction** (002 Sec III-C): eq (1) evaluated recursively over the horizon, guided by
  ``Π_GVP^k``: each step keeps the global plan's move along the surface (its components on
  ``ν_y`` and ``ν_z``) and replaces the move towards the surface with ``ν_x d_insp``, so the
  predicted pose sits ``d_view`` from the surface as measured now. Reading chosen: ``p_nn`` is
  taken at the pose reached after the step along the surface (the step is what would carry the
  robot to a different part of the surface), and only surface points within the camera's
  vertical half-footprint of that pose's height count, so a level sees its own part of the face.
  Eq (2) gives the yaw from the new pose. Where no surface point is in reach, the global pose is
  kept.
* **Deviation** (eq (3)): ``F_D`` is the discrete Fréchet distance of the two paths.
  Eq (3) as printed, ``1 / (1 + F_D)``, is a similarity (1 for identical paths) while the text
  and Algorithm 1 treat ``Γ_s > Γ_t`` as "the paths deviate". This implementation uses the
  deviation ``Γ_s = 1 - 1/(1 + F_D) = F_D / (1 + F_D)`` in [0, 1): 0 for identical paths,
  rising with the deviation, so ``Γ_s > Γ_t`` switches to the local path exactly as the text
  says. With the paper's ``Γ_t = 0.5`` both readings switch at ``F_D = 1`` m.
* **Alignment** (eq (4)): when ``Γ_s > Γ_t`` the global segment is re-projected onto the local
  one by the Kabsch transform, ``Π̂_GVP = U* Π_GVP + t*``; the RMSE to ``Π_LVP`` before and
  after shows how much of the deviation is rigid.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError, PlanningError
from seminspect.geometry.paths import apply_rigid, discrete_frechet, kabsch, paired_rmse
from seminspect.geometry.transforms import as_point, as_points
from seminspect.planning.view_planner import ViewConstraints, nearest_surface_point, viewing_frame

#: Γ_t of 002 Sec IV.
GAMMA_T = 0.5
#: Prediction horizon N (poses); the paper does not give it.
HORIZON = 3


def deviation_score(frechet: float) -> float:
    """``Γ_s`` of eq (3) in the deviation convention (module docstring): ``F_D / (1 + F_D)``."""
    if not (math.isfinite(frechet) and frechet >= 0):
        raise InvalidInputError(f"Fréchet distance must be finite and >= 0, got {frechet}")
    return frechet / (1.0 + frechet)


@dataclass(frozen=True)
class PredictedPath:
    """``Π_LVP``: predicted positions ``(N, 3)`` and yaws ``(N,)``; ``guided[i]`` is False where
    no surface was in reach and the global pose was kept."""

    positions: NDArray[np.float64]
    yaws: NDArray[np.float64]
    guided: NDArray[np.bool_]


def _local_frame(
    position: NDArray[np.float64], points: NDArray[np.float64], half: float
) -> tuple[NDArray[np.float64], float, tuple[NDArray[np.float64], ...]] | None:
    """``p_nn``, its distance and the frame ``ν_x, ν_y, ν_z`` at ``position``, from the points
    within ``half`` of its height; None when there are none (or the robot is on the surface)."""
    band = points[np.abs(points[:, 2] - position[2]) <= half]
    if not len(band):
        return None
    nearest, distance = nearest_surface_point(position, band)
    try:
        return nearest, distance, viewing_frame(position, nearest)
    except PlanningError:
        return None


def predict_local_path(
    position: ArrayLike,
    surface: ArrayLike,
    global_segment: ArrayLike,
    global_yaws: ArrayLike,
    constraints: ViewConstraints,
) -> PredictedPath:
    """Eq (1) recursed along ``global_segment`` from ``position`` (module docstring)."""
    here = as_point(position, "robot position")
    points = as_points(surface, "surface points", allow_empty=True)
    targets = as_points(global_segment, "global segment")
    yaws_in = np.asarray(global_yaws, dtype=np.float64).reshape(-1)
    if len(yaws_in) != len(targets):
        raise InvalidInputError(f"{len(yaws_in)} yaws for {len(targets)} global poses")
    half = constraints.d_view * math.tan(math.radians(constraints.vfov_deg) / 2)
    positions, yaws, guided = [], [], []
    previous = here
    for target, target_yaw in zip(targets, yaws_in, strict=True):
        step = target - previous
        pose = _guided_step(here, step, points, constraints, half)
        guided.append(pose is not None)
        if pose is None:
            pose = (target.copy(), float(target_yaw))
        positions.append(pose[0])
        yaws.append(pose[1])
        here, previous = pose[0], target
    return PredictedPath(np.array(positions), np.array(yaws), np.array(guided))


def _guided_step(
    here: NDArray[np.float64],
    step: NDArray[np.float64],
    points: NDArray[np.float64],
    constraints: ViewConstraints,
    half: float,
) -> tuple[NDArray[np.float64], float] | None:
    """One evaluation of eqs (1)-(2); None when no surface point is in reach."""
    start = _local_frame(here, points, half)
    if start is None:
        return None
    _, nu_y, nu_z = start[2]
    along = here + nu_y * float(step @ nu_y) + nu_z * float(step @ nu_z)
    stepped = _local_frame(along, points, half)
    if stepped is None:
        return None
    nearest, distance, (nu_x, _, _) = stepped
    target = along + nu_x * (distance - constraints.d_view)  # eq (1)
    facing = nearest - target
    return target, math.atan2(facing[1], facing[0])  # eq (2)


@dataclass(frozen=True)
class CycleDecision:
    """One cycle of Algorithm 1.

    Attributes:
        global_segment: ``Π_GVP^k`` ``(N, 3)``.
        local_path: ``Π_LVP^k``.
        frechet: ``F_D(Π_GVP^k, Π_LVP^k)`` [m].
        gamma_s: deviation ``Γ_s`` (eq (3), module docstring).
        adapt: ``Γ_s > Γ_t`` and adaptation is enabled: track ``Π_LVP``.
        aligned_global: ``Π̂_GVP^k`` of eq (4) (the global segment itself when not adapting).
        rmse_before, rmse_after: RMSE of ``Π_GVP`` and of the Kabsch-aligned ``Π_GVP`` to
            ``Π_LVP`` [m].
        seconds: wall time of predict + Fréchet + Kabsch.
    """

    global_segment: NDArray[np.float64]
    local_path: PredictedPath
    frechet: float
    gamma_s: float
    adapt: bool
    aligned_global: NDArray[np.float64]
    rmse_before: float
    rmse_after: float
    seconds: float


def plan_cycle(
    position: ArrayLike,
    surface: ArrayLike,
    global_segment: ArrayLike,
    global_yaws: ArrayLike,
    constraints: ViewConstraints,
    *,
    gamma_t: float = GAMMA_T,
    adaptive: bool = True,
) -> CycleDecision:
    """PredictLocalPlan, ComputePathSimilarity and ComputeAlignment of Algorithm 1."""
    started = time.perf_counter()
    segment = as_points(global_segment, "global segment")
    local = predict_local_path(position, surface, segment, global_yaws, constraints)
    frechet = discrete_frechet(segment, local.positions)
    gamma_s = deviation_score(frechet)
    rotation, translation = kabsch(segment, local.positions)
    aligned = apply_rigid(segment, rotation, translation)
    adapt = adaptive and gamma_s > gamma_t
    return CycleDecision(
        global_segment=segment,
        local_path=local,
        frechet=frechet,
        gamma_s=gamma_s,
        adapt=adapt,
        aligned_global=aligned if gamma_s > gamma_t else segment,
        rmse_before=paired_rmse(segment, local.positions),
        rmse_after=paired_rmse(aligned, local.positions),
        seconds=time.perf_counter() - started,
    )
