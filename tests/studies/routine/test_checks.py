"""The routine acceptance checks: met where the figures meet them, missed where they do not,
and counted over the seeds."""

import pytest

from seminspect.studies.routine.checks import (
    acceptance_checks,
    acceptance_lines,
    pair_checks,
    single_checks,
    task_gaps,
    tour_gap_line,
)
from seminspect.studies.routine.study import RoutinePair, RoutineStudy, TourTiming


def test_a_nominal_run_fails_where_the_change_score_reaches_the_threshold(make_metrics) -> None:
    assert all(single_checks("nominal", make_metrics()).values())
    checks = single_checks("nominal", make_metrics(gamma_s_max=0.5, viewpoint_utility_mean=0.69))
    assert checks == {"Γ_s below Γ_t throughout": False, "utility >= 0.7": False}
    blocked = single_checks("obstructed", make_metrics("obstructed", tasks_completed=2))
    assert blocked == {"every task completed": False, "no collision": True}


def test_an_adaptive_run_must_beat_the_baseline(make_metrics) -> None:
    baseline = make_metrics("receding", viewpoint_utility_mean=0.6, roi_coverage_pct=80.0)
    assert all(pair_checks(RoutinePair(make_metrics("receding"), baseline)).values())
    weak = make_metrics(
        "receding", viewpoint_utility_mean=0.65, roi_coverage_pct=80.0, rmse_after_kabsch_m=0.5
    )
    assert pair_checks(RoutinePair(weak, baseline)) == {
        "distance error <= 0.3 m after adapting": True,
        "utility +0.1 over baseline": False,  # 0.65 < 0.6 + 0.1
        "coverage above baseline": False,  # equal is not above
        "RMSE after Kabsch below before": False,
    }


@pytest.mark.parametrize("after", [None, 0.31])
def test_the_distance_check_fails_without_or_above_its_figure(make_metrics, after) -> None:
    adaptive = make_metrics("advancing", view_distance_mae_after_deviation_m=after)
    baseline = make_metrics("advancing", viewpoint_utility_mean=0.6, roi_coverage_pct=80.0)
    assert not pair_checks(RoutinePair(adaptive, baseline))[
        "distance error <= 0.3 m after adapting"
    ]


def test_the_lines_count_the_seeds_and_name_those_that_miss(make_metrics) -> None:
    runs = {
        seed: make_metrics(seed=seed, gamma_s_max=gamma)
        for seed, gamma in ((0, 0.3), (1, 0.6), (2, 0.3), (3, 0.7))
    }
    lines = acceptance_lines(acceptance_checks(RoutineStudy({"nominal": runs}, {}, (0, 1, 2, 3))))
    assert lines == [
        "- nominal: Γ_s below Γ_t throughout: met in 2 of 4 (not in seeds 1, 3)",
        "- nominal: utility >= 0.7: met in 4 of 4",
    ]


def test_the_tour_check_takes_every_task_of_every_adaptive_run(make_metrics) -> None:
    study = RoutineStudy(
        {"nominal": {0: make_metrics(gap_pct=1.0)}, "obstructed": {0: make_metrics(gap_pct=None)}},
        {"receding": {0: RoutinePair(make_metrics(gap_pct=6.0), make_metrics(gap_pct=9.0))}},
        (0,),
    )
    gaps = task_gaps(study)
    assert gaps == [1.0] * 3 + [6.0] * 3  # the baseline's tours are not SA's to answer for
    grids = [TourTiming(9, 8.0, 8.0, 0.0, 1.0, 1.0)]
    assert tour_gap_line(gaps, grids) == (
        "- SA-TSP within 5 % of LKH on every task: not met (largest gap 6.00 % over 6 tasks); "
        "on every grid: met"
    )
