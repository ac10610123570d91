"""The acceptance checks of 002's reproduction (issue 11's figures), per scenario and seed.

* nominal: Γ_s stays below Γ_t (0.5) throughout, and the mean viewpoint utility reaches 0.7
  (002 Fig 8: 0.71);
* obstructed: every task completed without a collision;
* receding and advancing: after adapting the viewing distance is within 0.3 m, the utility
  gains 0.1 and the coverage rises over the non-adaptive run, and Kabsch lowers the RMSE;
* SA-TSP stays within 5 % of LKH on every task and every view grid.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from seminspect.missions.routine.metrics import RoutineMetrics
from seminspect.studies.routine.study import RoutinePair, RoutineStudy, TourTiming

#: Checks by scenario and seed: each check's name and whether the run meets it.
Checks = dict[str, dict[int, dict[str, bool]]]


def single_checks(scenario: str, m: RoutineMetrics) -> dict[str, bool]:
    """The checks of an adaptive run alone: nominal's, or obstructed's for any other."""
    if scenario == "nominal":
        return {
            "Γ_s below Γ_t throughout": _known(m.gamma_s_max) < 0.5,
            "utility >= 0.7": _known(m.viewpoint_utility_mean) >= 0.7,
        }
    return {
        "every task completed": m.tasks_completed == m.tasks_total,
        "no collision": m.collisions == 0,
    }


def pair_checks(pair: RoutinePair) -> dict[str, bool]:
    """The checks of an adaptive run against the non-adaptive one on the same prior."""
    a, b = pair.adaptive, pair.baseline
    return {
        "distance error <= 0.3 m after adapting": _known(a.view_distance_mae_after_deviation_m)
        <= 0.3,
        "utility +0.1 over baseline": _known(a.viewpoint_utility_mean)
        >= _known(b.viewpoint_utility_mean) + 0.1,
        "coverage above baseline": _known(a.roi_coverage_pct) > _known(b.roi_coverage_pct),
        "RMSE after Kabsch below before": _known(a.rmse_after_kabsch_m)
        < _known(a.rmse_before_kabsch_m),
    }


def _known(value: float | None) -> float:
    """A figure a check compares; one a run lacks is NaN, which meets no check."""
    return math.nan if value is None else value


def acceptance_checks(study: RoutineStudy) -> Checks:
    """Every check, per scenario and seed."""
    checks: Checks = {}
    for scenario, runs in study.single.items():
        checks[scenario] = {seed: single_checks(scenario, m) for seed, m in runs.items()}
    for scenario, pairs in study.pairs.items():
        checks[scenario] = {seed: pair_checks(pair) for seed, pair in pairs.items()}
    return checks


def acceptance_lines(checks: Checks) -> list[str]:
    """One line per scenario and check: in how many seeds it is met, and which miss it."""
    lines = []
    for scenario, by_seed in checks.items():
        for check in next(iter(by_seed.values())):
            missed = [seed for seed, found in by_seed.items() if not found[check]]
            met = len(by_seed) - len(missed)
            plural = "s" if len(missed) > 1 else ""
            note = f" (not in seed{plural} {', '.join(map(str, missed))})" if missed else ""
            lines.append(f"- {scenario}: {check}: met in {met} of {len(by_seed)}{note}")
    return lines


def task_gaps(study: RoutineStudy) -> list[float]:
    """SA's gap to LKH on every task of every adaptive run [%]."""
    return [
        t.tour["gap_pct"] for m in study.adaptive_runs() for t in m.tasks if "gap_pct" in t.tour
    ]


def tour_gap_line(gaps: Sequence[float], tours: Sequence[TourTiming]) -> str:
    """Whether SA-TSP stays within 5 % of LKH on every task and on every view grid."""
    return (
        f"- SA-TSP within 5 % of LKH on every task: {'met' if max(gaps) <= 5.0 else 'not met'} "
        f"(largest gap {max(gaps):.2f} % over {len(gaps)} tasks); on every grid: "
        f"{'met' if all(r.gap_pct <= 5.0 for r in tours) else 'not met'}"
    )
