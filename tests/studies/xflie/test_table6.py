"""The planning study's Table 6 tables: over the seeds, on the targets two planners share, and
one planner's rows regenerated among the others."""

import dataclasses
import math
from pathlib import Path

import pytest

from seminspect.studies.xflie.missions import MissionOutcome
from seminspect.studies.xflie.table6 import common_target_rmse, merge_table6_rows, table6_summary


def _outcome(planner: str, seed: int, errors: dict[str, float], load: float) -> MissionOutcome:
    return MissionOutcome(
        "small", planner, Path(f"runs/{planner}{seed}"), 180.0, load, 1.0, 100.0, 40.0,
        math.sqrt(sum(e * e for e in errors.values()) / len(errors)), len(errors), 5, 700.0,
        30.0, 20, seed, errors,
    )  # fmt: skip


def test_table_6_compares_the_planners_on_the_targets_both_inspected() -> None:
    outcomes = [
        _outcome("hierarchical", 0, {"car-0": 0.1, "car-1": 0.3}, 0.02),
        _outcome("volumetric", 0, {"car-0": 0.2, "car-2": 0.9}, 0.04),
        _outcome("hierarchical", 1, {"car-3": 0.4}, 0.04),
        _outcome("volumetric", 1, {"car-3": 0.5, "car-4": 0.1}, 0.06),
    ]
    # car-0 in seed 0 and car-3 in seed 1 were inspected by both
    assert common_target_rmse(outcomes, "hierarchical") == pytest.approx(math.sqrt(0.17 / 2))
    assert common_target_rmse(outcomes, "volumetric") == pytest.approx(math.sqrt(0.29 / 2))
    assert common_target_rmse(outcomes[:1], "hierarchical") is None  # no volumetric run
    rows = table6_summary(outcomes).splitlines()
    # mean ± sample standard deviation over the seeds: 0.02 and 0.04 -> 0.030 ± 0.014
    assert rows[2].startswith("| small | hierarchical | 0, 1 | 0.030 ± 0.014 | 180.0 ± 0.0 (42.7)")
    assert f"| {math.sqrt(0.17 / 2):.3f} | 2 / 5; 1 / 5 | 700 ± 0 |" in rows[2]
    assert rows[3].startswith("| small | volumetric | 0, 1 | 0.050 ± 0.014 |")


def test_the_frontier_row_stands_beside_gbplanner_and_is_compared_with_xflie() -> None:
    explorer = dataclasses.replace(
        _outcome("frontier", 0, {"car-0": 1.5, "car-1": 2.0, "car-4": 0.5}, 0.01),
        inspected=0,
        found=4,
    )
    outcomes = [_outcome("hierarchical", 0, {"car-0": 0.1, "car-1": 0.3}, 0.02), explorer]
    # Like for like with xFLIE: car-0 and car-1, which xFLIE inspected and the explorer found.
    assert common_target_rmse(outcomes, "frontier") == pytest.approx(math.sqrt(6.25 / 2))
    row = table6_summary(outcomes).splitlines()[3]
    assert row.startswith("| small | frontier | 0 | 0.010 | 180.0 (87.6) | 100.0 (64.2) |")
    assert "(0.660)" in row and "| found 4 / 5 |" in row


def test_regenerating_one_planner_keeps_the_other_rows_in_order() -> None:
    hierarchical = _outcome("hierarchical", 0, {"car-0": 0.1}, 0.02)
    volumetric = _outcome("volumetric", 0, {"car-0": 0.2}, 0.04)
    explorer = dataclasses.replace(_outcome("frontier", 0, {"car-0": 1.0}, 0.01), found=3)
    current = table6_summary([hierarchical, volumetric])
    merged = merge_table6_rows(current, table6_summary([explorer]))
    lines = merged.splitlines()
    assert lines[:2] == current.splitlines()[:2]
    planners = [line.split("|")[2].strip() for line in lines[2:]]
    assert planners == ["hierarchical", "volumetric", "frontier"]
    assert lines[2:4] == current.splitlines()[2:4]  # the kept rows, unchanged
    newer = dataclasses.replace(explorer, found=5)
    assert "found 5 / 5" in merge_table6_rows(merged, table6_summary([newer]))
    assert merge_table6_rows(merged, table6_summary([newer])).count("| frontier |") == 1
