"""002's routine-inspection scenarios run over seeds, and SA-TSP timed against LKH.

Runs, on the 20 m mine drift with the paper's parameters (d_view 2 m, γ_H 0.6, α 69.5°,
β 45°, Γ_t 0.5), each scenario over the seeds (each seed draws its own site and change):

* nominal (002 Fig 8), adaptive;
* receding (Figs 9 vs 11) and advancing, adaptive and non-adaptive on one M_H;
* obstructed, adaptive;

then times SA-TSP against LKH (elkai) on view grids of growing size. Simulated figures do not
depend on the machine's speed; the timings do.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from seminspect.core.errors import SeminspectError
from seminspect.core.rng import make_rng
from seminspect.missions.routine.config import RoutineConfig
from seminspect.missions.routine.metrics import RoutineMetrics
from seminspect.missions.routine.run import PRIOR_FILE, RoutineResult, run_routine
from seminspect.planning.global_views import InspectionRegion, grid_points
from seminspect.planning.tour import annealed_tour, reference_tour

SEEDS = (0, 1, 2, 3, 4)
#: Scenarios run adaptive alone, and those run both ways on one prior.
SINGLE = ("nominal", "obstructed")
PAIRED = ("receding", "advancing")
#: View grids for the tour comparison: rectangle width x height [m] on a wall.
GRIDS = ((2.4, 1.6), (6.0, 3.0), (12.0, 4.0), (24.0, 4.0))


@dataclass(frozen=True)
class RoutinePair:
    """One scenario and seed run adaptive and non-adaptive on the same ``M_H``."""

    adaptive: RoutineMetrics
    baseline: RoutineMetrics


@dataclass(frozen=True)
class RoutineStudy:
    """Every scenario over the seeds: ``single[scenario][seed]`` the adaptive run's figures,
    ``pairs[scenario][seed]`` the adaptive and non-adaptive runs on one prior."""

    single: dict[str, dict[int, RoutineMetrics]]
    pairs: dict[str, dict[int, RoutinePair]]
    seeds: tuple[int, ...]

    def adaptive_runs(self) -> list[RoutineMetrics]:
        """The figures of every adaptive run: the single scenarios', then the pairs'."""
        runs = [m for runs in self.single.values() for m in runs.values()]
        return runs + [pair.adaptive for pairs in self.pairs.values() for pair in pairs.values()]

    def to_json(self) -> dict[str, Any]:
        """Every figure as plain JSON values, each run as its ``metrics.json`` holds it."""
        return {
            "single": {
                scenario: {seed: m.to_json() for seed, m in runs.items()}
                for scenario, runs in self.single.items()
            },
            "pairs": {
                scenario: {
                    seed: {"adaptive": p.adaptive.to_json(), "baseline": p.baseline.to_json()}
                    for seed, p in pairs.items()
                }
                for scenario, pairs in self.pairs.items()
            },
            "seeds": list(self.seeds),
        }


@dataclass(frozen=True)
class TourTiming:
    """SA-TSP against LKH on one view grid (lengths in metres, times in milliseconds)."""

    views: int
    sa_length_m: float
    lkh_length_m: float
    gap_pct: float
    sa_ms: float
    lkh_ms: float


def run_study(out: Path, seeds: tuple[int, ...] = SEEDS) -> RoutineStudy:
    """Every scenario over ``seeds``, each run in its own directory under ``out``."""
    single = {
        scenario: {
            seed: _finished(
                run_routine(RoutineConfig(scenario=scenario, seed=seed), out / f"{scenario}-{seed}")
            )
            for seed in seeds
        }
        for scenario in SINGLE
    }
    pairs = {
        scenario: {seed: run_pair(out, scenario, seed) for seed in seeds} for scenario in PAIRED
    }
    return RoutineStudy(single, pairs, tuple(seeds))


def run_pair(out: Path, scenario: str, seed: int) -> RoutinePair:
    """The adaptive run, then the non-adaptive one on the ``M_H`` the adaptive run recorded."""
    adaptive = run_routine(
        RoutineConfig(scenario=scenario, seed=seed), out / f"{scenario}-{seed}-a"
    )
    prior = adaptive.run_dir / PRIOR_FILE
    baseline = run_routine(
        RoutineConfig(scenario=scenario, seed=seed, adapt=False),
        out / f"{scenario}-{seed}-b",
        prior_path=prior,
    )
    return RoutinePair(_finished(adaptive), _finished(baseline))


def _finished(result: RoutineResult) -> RoutineMetrics:
    if result.metrics is None:
        raise SeminspectError(
            f"{result.run_dir}: the routine run stopped before its mission was built "
            f"({result.reason})"
        )
    return result.metrics


def tour_study() -> list[TourTiming]:
    """SA-TSP against LKH on view grids of growing size (start 2 m off the grid's corner)."""
    config = RoutineConfig()
    rows = []
    for width, height in GRIDS:
        corners = [
            [10.0, 0, 0.5],
            [10.0, width, 0.5],
            [10.0, width, 0.5 + height],
            [10.0, 0, 0.5 + height],
        ]
        region = InspectionRegion(f"{width}x{height}", np.array(corners, dtype=np.float64))
        views = grid_points(region, config.view_constraints()) - [2.0, 0.0, 0.0]
        start = views[0] - [0.0, 2.0, 0.0]
        t0 = time.perf_counter()
        sa = annealed_tour(start, views, make_rng(0, "bench", "tour"))
        t1 = time.perf_counter()
        lkh = reference_tour(start, views)
        t2 = time.perf_counter()
        rows.append(
            TourTiming(
                views=len(views),
                sa_length_m=sa.length,
                lkh_length_m=lkh.length,
                gap_pct=100 * (sa.length / lkh.length - 1),
                sa_ms=1e3 * (t1 - t0),
                lkh_ms=1e3 * (t2 - t1),
            )
        )
    return rows
