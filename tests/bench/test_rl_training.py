"""bench/rl_training.py on a progress.csv written by the trainer's own log."""

from __future__ import annotations

import math

import pytest

from bench_scripts import bench_script
from seminspect.missions.learning.progress import ProgressLog, ProgressRow

rl_training = bench_script("rl_training")


def _row(update: int, obstacles: int, episodes: int, coverage: float, crash: float) -> ProgressRow:
    no_episode = episodes == 0
    return ProgressRow(
        update=update, steps=update * 100, wall_s=float(update), steps_per_s=100.0,
        obstacles=obstacles, episodes=episodes, mean_return=math.nan if no_episode else 1.0,
        coverage_pct=math.nan if no_episode else coverage,
        crash_pct=math.nan if no_episode else crash, timeout_pct=math.nan if no_episode else 0.0,
        policy_loss=0.0, value_loss=0.0, entropy=0.0, approx_kl=0.0, clip_fraction=0.0, lr=1e-4,
    )  # fmt: skip


@pytest.fixture
def run_dir(tmp_path):
    log = ProgressLog(tmp_path)
    for row in (
        _row(1, 0, 1, 10.0, 100.0),  # steps 100: the first window (1-200)
        _row(2, 0, 3, 50.0, 0.0),  # steps 200
        _row(3, 4, 0, 0.0, 0.0),  # steps 300, no episode ended: blank cells
        _row(4, 9, 2, 80.0, 50.0),  # steps 400
    ):
        log.add(row)
    log.close()
    return tmp_path


def test_windows_weigh_each_update_by_its_episodes(run_dir):
    found = rl_training.windows(rl_training.read_rows(run_dir), size=200)
    first, second = found[0], found[200]
    assert (first.obstacles, first.episodes) == ("0", 4)
    assert first.coverage_pct == pytest.approx((10.0 + 3 * 50.0) / 4)  # not the rows' mean
    assert first.crash_pct == pytest.approx(25.0)
    assert (second.obstacles, second.episodes) == ("4-9", 2)  # the blank row adds nothing
    assert (second.coverage_pct, second.crash_pct) == (80.0, 50.0)


def test_the_table_has_a_row_per_window_and_a_column_per_run(run_dir):
    found = rl_training.windows(rl_training.read_rows(run_dir), size=200)
    lines = rl_training.table({"a": found, "b": {0: found[0]}}, size=200)
    assert len(lines) == 4 and lines[0].count("coverage %") == 2
    assert lines[2].endswith("| 0, 40.0, 25.0 (4) | 0, 40.0, 25.0 (4) |")
    assert lines[3].endswith("| 4-9, 80.0, 50.0 (2) |  |")


def test_a_directory_without_progress_is_one_clear_error(tmp_path):
    with pytest.raises(SystemExit, match=r"progress\.csv does not exist"):
        rl_training.read_rows(tmp_path)
