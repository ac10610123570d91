"""bench/reproduction.py: a Table 3 row is the statistics of its seeds, beside the paper's row."""

from __future__ import annotations

from bench_scripts import bench_script
from seminspect.runs.sweep import SweepTask

reproduction = bench_script("reproduction")


def _run(seed: int, feature: int, rmse: float, sim_s: float, false_targets: int = 0):
    task = SweepTask(f"city-small-seed{seed}", "city small", {"seed": seed}, "unused", seed)
    metrics = {
        "table3": {
            "target": [6, 14], "level": [10, 5], "pose": [130 + seed, 130 + seed],
            "feature": [feature, feature // 2], "unified": [228, 241],
            "reconciled_pct": 24.0 + seed, "detected_pct": 100.0, "inspected_pct": 100.0,
        },
        "table6": {
            "localisation_rmse_m": rmse, "surface_coverage_pct": 48.0, "bbox_volume_m3": 130.0,
        },
        "targets": {"false_targets": false_targets},
        "mission": {
            "collisions": 0, "sim_time_s": sim_s, "level_endings": {"similarity": 5, "cap": 0},
        },
    }  # fmt: skip
    return task, metrics


def test_a_table_3_row_gives_counts_as_median_and_range_and_figures_as_mean_and_spread() -> None:
    runs = [_run(0, 150, 0.06, 1100.0), _run(1, 160, 0.07, 1200.0), _run(2, 170, 0.08, 1150.0, 1)]
    cells = [cell.strip() for cell in reproduction.table3_row("city small", runs).split("|")[1:-1]]
    header = [cell.strip() for cell in reproduction.HEADER.splitlines()[0].split("|")[1:-1]]
    assert len(cells) == len(header)
    row = dict(zip(header, cells, strict=True))
    assert row["seeds"] == "0-2"
    assert row["Target"] == "6/14"  # every seed agrees: no range
    assert row["Pose"] == "131 [130-132]/131 [130-132]"
    assert row["Feature"] == "160 [150-170]/80 [75-85]"
    assert row["RMSE xy (m)"] == "0.070 ± 0.010"
    assert row["sim s"] == "1150 ± 50"
    assert row["false targets"] == "0 [0-1]"
    assert row["Reconciled %"] == "25.0 ± 1.0"


def test_the_papers_row_stands_in_the_same_columns() -> None:
    paper = reproduction.paper_row("large").split("|")[1:-1]
    assert len(paper) == len(reproduction.HEADER.splitlines()[0].split("|")[1:-1])
    assert [cell.strip() for cell in paper[2:6]] == ["20/40", "40/23", "469/452", "219/121"]
    assert paper[8].strip() == "95/100" and paper[10].strip() == "0.24"
