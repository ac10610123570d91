"""bench/compare_runs.py flags a column that moved between two sets of missions, and only that."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from bench_scripts import bench_script
from seminspect.missions.xflie.sweep import MISSIONS
from seminspect.runs.sweep import SweepRow, sweep_tables

REPO = Path(__file__).resolve().parents[2]
#: The envelope's figures under the sweep's column names.
SWEEP_NAMES = {
    "target_nodes": "target_nodes",
    "level_nodes": "level_nodes",
    "pose_nodes": "pose_nodes",
    "feature_nodes": "feature_nodes",
    "unified_nodes": "unified_nodes",
    "unified_edges": "unified_edges",
    "reconciled_pct": "reconciled_pct",
    "detected_pct": "detected_pct",
    "inspected_pct": "inspected_pct",
    "rmse_xy_m": "rmse_xy_m",
    "coverage_pct": "surface_coverage_pct",
    "bbox_volume_m3": "bbox_volume_m3",
    "sim_s": "sim_time_s",
}


compare_runs = bench_script("compare_runs")


def _city_small_runs() -> list[dict[str, float]]:
    """The recorded city small missions (the golden envelope's seeds), as sweep figures."""
    path = REPO / "tests/missions/xflie/data/golden/city-small-envelope.json"
    runs = json.loads(path.read_text(encoding="utf-8"))["runs"]
    return [{column: run[name] for column, name in SWEEP_NAMES.items()} for run in runs]


def _write_sweep(directory: Path, runs: list[dict[str, float]], **scaled: float) -> Path:
    rows = [
        SweepRow(
            f"city-small-seed{seed}",
            "city small",
            seed,
            "completed",
            figures={k: v * scaled.get(k, 1.0) for k, v in run.items()},
        )
        for seed, run in enumerate(runs)
    ]
    sweep_tables(rows, directory, MISSIONS.columns)
    return directory


def test_a_twenty_percent_rise_in_rmse_is_flagged_and_nothing_else(tmp_path: Path) -> None:
    runs = _city_small_runs()
    before = compare_runs.read_runs(_write_sweep(tmp_path / "before", runs))
    worse = compare_runs.read_runs(_write_sweep(tmp_path / "after", runs, rmse_xy_m=1.2))
    flagged = [c.column for c in compare_runs.compare(before, worse) if c.flagged]
    assert flagged == ["rmse_xy_m"]
    same = compare_runs.compare(before, before)
    assert same and not any(c.flagged for c in same)
    assert all(c.p_value == 1.0 for c in same if len(set(c.before)) == 1)


def test_five_seeds_against_five_see_a_clear_shift_only(tmp_path: Path) -> None:
    # With five seeds a side, the smallest p-value is 2/252 = 0.008: a shift that separates the
    # two sets completely is flagged, a shift by less than the seeds' spread is not.
    runs = _city_small_runs()[:5]
    before = compare_runs.read_runs(_write_sweep(tmp_path / "before", runs))
    apart = compare_runs.read_runs(_write_sweep(tmp_path / "apart", runs, sim_s=1.5))
    slightly = compare_runs.read_runs(_write_sweep(tmp_path / "slightly", runs, sim_s=1.01))
    assert [c.column for c in compare_runs.compare(before, apart) if c.flagged] == ["sim_s"]
    assert not any(c.flagged for c in compare_runs.compare(before, slightly))


def test_the_command_exits_one_on_a_difference_and_says_why_it_cannot_compare(
    tmp_path: Path, capsys
) -> None:
    runs = _city_small_runs()
    before = _write_sweep(tmp_path / "before", runs)
    after = _write_sweep(tmp_path / "after", runs, rmse_xy_m=1.2)
    assert compare_runs.main([str(before), str(after)]) == 1
    assert "1 of " in capsys.readouterr().out
    assert compare_runs.main([str(before), str(before / "sweep.csv")]) == 0
    with pytest.raises(SystemExit, match="cannot read"):
        compare_runs.main([str(before), str(tmp_path / "missing")])
    (tmp_path / "other.csv").write_text("a,b\n1,2\n", encoding="utf-8")
    with pytest.raises(SystemExit, match="not a sweep table"):
        compare_runs.main([str(before), str(tmp_path / "other.csv")])
    with pytest.raises(SystemExit, match="not in both"):
        compare_runs.main([str(before), str(after), "--group", "campus"])


def test_the_published_runs_hold_at_least_five_seeds_a_group() -> None:
    published = compare_runs.read_runs(REPO / "docs/data/reproduction/sweep.csv")
    assert published and all(len(runs) >= 5 for runs in published.values())
    assert not any(c.flagged for c in compare_runs.compare(published, published))


def test_a_figure_that_is_not_a_number_is_named_by_its_line(tmp_path: Path) -> None:
    table = tmp_path / "sweep.csv"
    table.write_text("run,group,seed,state,rmse_xy_m\na,g,0,completed,abc\n", encoding="utf-8")
    with pytest.raises(SystemExit, match=r"sweep.csv, line 2: could not convert"):
        compare_runs.read_runs(table)
