"""The routine tables of docs/reproduction.md: a row's statistics over the seeds, and the
sections written from one study."""

from seminspect.studies.routine.study import RoutinePair, RoutineStudy, TourTiming
from seminspect.studies.routine.tables import (
    pair_table,
    reproduction_sections,
    single_table,
    tours_table,
)


def _cells(table: str, row: int) -> list[str]:
    return [cell.strip() for cell in table.splitlines()[row].split("|")[1:-1]]


def test_a_row_gives_figures_as_mean_and_spread_and_counts_as_median_and_range(
    make_metrics,
) -> None:
    runs = {
        seed: make_metrics(
            seed=seed, gamma_s_max=gamma, time_s=time_s, tasks_completed=done, collisions=0
        )
        for seed, gamma, time_s, done in (
            (0, 0.30, 40.0, 3),
            (1, 0.40, 42.0, 2),
            (2, 0.50, 44.0, 3),
        )
    }
    table = single_table(RoutineStudy({"nominal": runs}, {}, (0, 1, 2)))
    header = _cells(table, 0)
    row = dict(zip(header, _cells(table, 2), strict=True))
    assert row["scenario"] == "nominal" and row["seeds"] == "0-2"
    assert row["Γ_s max"] == "0.40 ± 0.10"  # mean ± sample standard deviation
    assert row["mean utility"] == "0.750 ± 0.000"
    assert row["task time s (first task)"] == "42.0 ± 2.0"
    assert row["tasks completed"] == "3 [2-3] of 3"  # median [min-max] where seeds differ
    assert row["collisions"] == "0"


def test_a_pair_row_puts_adaptive_beside_non_adaptive(make_metrics) -> None:
    pairs = {
        seed: RoutinePair(
            make_metrics("receding", seed, change={"depth_m": depth}, roi_coverage_pct=90.0),
            make_metrics("receding", seed, roi_coverage_pct=80.0 + seed),
        )
        for seed, depth in ((0, 0.8), (2, 1.0))
    }
    row = _cells(pair_table(RoutineStudy({}, {"receding": pairs}, (0, 2))), 2)
    assert row[:3] == ["receding", "0, 2", "0.90 ± 0.14"]  # the recess's depth
    assert row[6] == "90.0 ± 0.0 / 81.0 ± 1.4"  # ROI coverage: adaptive / non-adaptive
    assert row[7] == "0.40 ± 0.00 / 0.10 ± 0.00" and row[8] == "4 of 10"


def test_the_sections_hold_the_tables_and_the_checks(make_metrics) -> None:
    study = RoutineStudy(
        {"nominal": {0: make_metrics(gap_pct=2.5)}},
        {"advancing": {0: RoutinePair(make_metrics("advancing"), make_metrics("advancing"))}},
        (0,),
    )
    tours = [TourTiming(9, 8.2, 8.0, 2.5, 443.7, 4.9)]
    sections = reproduction_sections(study, tours)
    assert list(sections) == [
        "routine-single",
        "routine-pairs",
        "routine-acceptance",
        "routine-tours",
    ]
    assert sections["routine-tours"] == tours_table(tours)
    assert _cells(sections["routine-tours"], 2) == ["9", "8.20", "8.00", "2.50", "444", "5"]
    acceptance = sections["routine-acceptance"].splitlines()
    assert acceptance[0] == "- nominal: Γ_s below Γ_t throughout: met in 1 of 1"
    assert "- advancing: utility +0.1 over baseline: met in 0 of 1 (not in seed 0)" in acceptance
    assert acceptance[-1] == (
        "- SA-TSP within 5 % of LKH on every task: met (largest gap 2.50 % over 6 tasks); "
        "on every grid: met"
    )
