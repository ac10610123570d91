"""Training logs: episode statistics from the env's info, and progress.csv rewritten whole."""

from __future__ import annotations

import csv
import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np

from seminspect.missions.learning.progress import EpisodeStats, ProgressLog, ProgressRow


def test_episode_stats_keep_only_the_rooms_that_ended():
    stats = EpisodeStats()
    stats.record({"coverage": np.zeros(2)})  # nothing ended in this step
    episode = {
        "return": np.array([1.0, 2.0, 3.0]),
        "coverage": np.array([0.5, 0.9, 0.1]),
        "crash": np.array([False, True, False]),
        "timeout": np.array([False, False, True]),
    }
    stats.record({"episode": episode, "_episode": np.array([False, True, True])})
    assert stats.returns == [2.0, 3.0] and stats.crashes == [True, False]
    assert stats.mean(stats.coverage, 100.0) == 50.0
    assert math.isnan(EpisodeStats().mean([]))


def test_the_log_rewrites_progress_csv_with_blank_cells_for_nothing(tmp_path: Path):
    names = [field.name for field in dataclasses.fields(ProgressRow)]
    log = ProgressLog(tmp_path)
    try:
        for update in (1, 2):
            values: dict[str, Any] = dict.fromkeys(names, 0.5)
            values |= {"update": update, "steps": 10 * update}
            log.add(ProgressRow(**values | {"obstacles": None, "mean_return": math.nan}))
    finally:
        log.close()
    with (tmp_path / "progress.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert [row["steps"] for row in rows] == ["10", "20"]
    assert rows[0]["obstacles"] == "" and rows[0]["mean_return"] == ""
    assert rows[1]["lr"] == "0.5"


def test_a_resumed_log_goes_on_from_the_saved_rows_not_the_file(tmp_path: Path):
    names = [field.name for field in dataclasses.fields(ProgressRow)]

    def row(update: int) -> ProgressRow:
        values: dict[str, Any] = dict.fromkeys(names, 0.5)
        return ProgressRow(**values | {"update": update, "steps": update})

    first = ProgressLog(tmp_path)
    for update in (1, 2, 3):  # 3 was logged after the last saved state
        first.add(row(update))
    first.close()
    resumed = ProgressLog(tmp_path, first.rows[:2])
    resumed.add(row(3))
    resumed.close()
    with (tmp_path / "progress.csv").open() as handle:
        assert [int(r["update"]) for r in csv.DictReader(handle)] == [1, 2, 3]
