"""A routine run's metrics: typed, under their own format tag, and runs made before the tag
existed still read."""

from __future__ import annotations

import pytest

from seminspect.core.errors import FileFormatError
from seminspect.core.io import write_versioned_json
from seminspect.missions.routine.measures import RegionChange
from seminspect.missions.routine.metrics import (
    LEGACY_METRICS_FORMAT,
    METRICS_FORMAT,
    RoutineMetrics,
    RoutineScenario,
    TaskFigures,
    read_routine_metrics,
)


def _metrics() -> RoutineMetrics:
    task = TaskFigures(
        "face", 12, 1, 0, 8.5, 12, True, "", 3.0, 50.0, 91.5, {"gap_pct": 0.4}, 47.0
    )  # fmt: skip
    return RoutineMetrics(
        "completed", "1 of 1 tasks completed", RoutineScenario("receding", 0, {"kind": "receding"}),
        True, 0.83, 0.17, 0.2, 91.5, 1, 1, 0, 0.54, 0.2, 3, 12, 0.4, 0.05, 2.5, 9.0, 0.4,
        60.0, 4.0, 15.0, [task], [RegionChange("face", 0.0, 1.25, 40.0)],
    )  # fmt: skip


@pytest.mark.parametrize("tag", [METRICS_FORMAT, LEGACY_METRICS_FORMAT])
def test_metrics_read_back_under_their_own_tag_and_the_old_one(tmp_path, tag: str) -> None:
    metrics = _metrics()
    write_versioned_json(tmp_path / "metrics.json", tag, 1, metrics.to_json())
    assert read_routine_metrics(tmp_path) == metrics
    assert metrics.to_json()["change_report"] == [
        {"region": "face", "added_m3": 0.0, "removed_m3": 1.25, "compared_m3": 40.0}
    ]


def test_a_missions_metrics_are_not_taken_for_a_routine_runs(tmp_path) -> None:
    write_versioned_json(tmp_path / "metrics.json", LEGACY_METRICS_FORMAT, 1, {"state": "x"})
    with pytest.raises(FileFormatError, match="not a routine run's metrics"):
        read_routine_metrics(tmp_path)
    write_versioned_json(tmp_path / "metrics.json", "seminspect.other", 1, {})
    with pytest.raises(FileFormatError, match=r"seminspect\.routine-metrics"):
        read_routine_metrics(tmp_path)
