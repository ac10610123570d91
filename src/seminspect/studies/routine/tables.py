"""The routine tables of docs/reproduction.md (002), from a :class:`~.study.RoutineStudy`.

Continuous figures are the mean ± standard deviation over the seeds, counts the median and
range; each row names its seeds.
"""

from __future__ import annotations

from collections.abc import Sequence

from seminspect.missions.routine.metrics import RoutineMetrics
from seminspect.report.markdown import mean_sd, median_range, seeds_cell
from seminspect.studies.routine.checks import (
    acceptance_checks,
    acceptance_lines,
    task_gaps,
    tour_gap_line,
)
from seminspect.studies.routine.study import RoutineStudy, TourTiming


def single_table(study: RoutineStudy) -> str:
    """Nominal and obstructed runs over the seeds."""
    lines = [
        "| scenario | seeds | Γ_s max | mean utility | viewing-distance MAE m | ROI coverage % "
        "| task time s (first task) | tasks completed | collisions |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for scenario, runs in study.single.items():
        ms = list(runs.values())
        lines.append(
            f"| {scenario} | {seeds_cell(list(runs))} "
            f"| {mean_sd((m.gamma_s_max for m in ms), 2)} "
            f"| {mean_sd((m.viewpoint_utility_mean for m in ms), 3)} "
            f"| {mean_sd((m.view_distance_mae_m for m in ms), 2)} "
            f"| {mean_sd((m.roi_coverage_pct for m in ms), 1)} "
            f"| {mean_sd((m.tasks[0].time_s for m in ms), 1)} "
            f"| {median_range(m.tasks_completed for m in ms)} of "
            f"{median_range(m.tasks_total for m in ms)} "
            f"| {median_range(m.collisions for m in ms)} |"
        )
    return "\n".join(lines)


def _change_m(metrics: RoutineMetrics) -> float:
    """How far the site changed: the recess's depth, or how far the face advanced [m]."""
    change = metrics.scenario.change
    return change.get("depth_m", change.get("advance_m", 0.0))


def pair_table(study: RoutineStudy) -> str:
    """Receding and advancing, adaptive / non-adaptive, over the seeds."""
    lines = [
        "| scenario | seeds | change m | Γ_s max | distance MAE after (m) | utility "
        "| ROI coverage % | RMSE before / after Kabsch (m) | adapted cycles |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for scenario, pairs in study.pairs.items():
        a = [pair.adaptive for pair in pairs.values()]
        b = [pair.baseline for pair in pairs.values()]

        def both(
            key: str, digits: int, a: list[RoutineMetrics] = a, b: list[RoutineMetrics] = b
        ) -> str:
            return (
                f"{mean_sd((getattr(m, key) for m in a), digits)} / "
                f"{mean_sd((getattr(m, key) for m in b), digits)}"
            )

        lines.append(
            f"| {scenario} | {seeds_cell(list(pairs))} | {mean_sd(map(_change_m, a), 2)} "
            f"| {mean_sd((m.gamma_s_max for m in a), 2)} "
            f"| {both('view_distance_mae_after_deviation_m', 2)} "
            f"| {both('viewpoint_utility_mean', 3)} | {both('roi_coverage_pct', 1)} "
            f"| {mean_sd((m.rmse_before_kabsch_m for m in a), 2)} / "
            f"{mean_sd((m.rmse_after_kabsch_m for m in a), 2)} "
            f"| {median_range(m.adapted_cycles for m in a)} of "
            f"{median_range(m.cycles for m in a)} |"
        )
    return "\n".join(lines)


def tours_table(tours: Sequence[TourTiming]) -> str:
    """SA-TSP against LKH, one row per view grid."""
    lines = ["| views | SA m | LKH m | gap % | SA ms | LKH ms |", "|---|---|---|---|---|---|"]
    lines += [
        f"| {r.views} | {r.sa_length_m:.2f} | {r.lkh_length_m:.2f} | "
        f"{r.gap_pct:.2f} | {r.sa_ms:.0f} | {r.lkh_ms:.0f} |"
        for r in tours
    ]
    return "\n".join(lines)


def reproduction_sections(study: RoutineStudy, tours: Sequence[TourTiming]) -> dict[str, str]:
    """The routine sections of docs/reproduction.md: the tables and the acceptance checks."""
    lines = acceptance_lines(acceptance_checks(study))
    lines.append(tour_gap_line(task_gaps(study), tours))
    return {
        "routine-single": single_table(study),
        "routine-pairs": pair_table(study),
        "routine-acceptance": "\n".join(lines),
        "routine-tours": tours_table(tours),
    }
