"""The planning study's tables, figure and JSON."""

import dataclasses
import json
import math
from pathlib import Path

import pytest

from seminspect.core.io import read_versioned_json
from seminspect.studies.xflie.study import MissionOutcome
from seminspect.studies.xflie.tables import (
    both_volumes_beside_paper,
    common_target_rmse,
    merge_table6_rows,
    study_markdown,
    table6_summary,
    write_study,
)
from study_fakes import study


def test_the_markdown_puts_the_papers_numbers_beside_ours() -> None:
    text = study_markdown(study(vp_s=0.06))
    assert "Visit front-bumper-1 in Level-0 of car-2" in text  # ours
    assert "Visit front-glass-1 in Level-1 of truck-16" in text  # the paper's scenario 3 row
    assert "| S3 ours | S3 paper |" in text
    assert "graph edges 97.6% of 41" in text
    assert "| large | 0 | volumetric | 101.0 (118.4) |" in text  # Table 6 beside the paper's
    assert "targets" not in text.split("## Hierarchical")[0]  # judged by bench/, not here


def test_the_study_is_written_as_markdown_json_and_a_figure(tmp_path: Path) -> None:
    written = write_study(study(), tmp_path)
    assert written["figure"].read_bytes()[:4] == b"\x89PNG"
    document = read_versioned_json(written["json"], "seminspect.planning-study", [1])
    first = document["table5"][0]["queries"][0]
    assert first["vp"][2]["time_s"] is None and first["vp"][2]["error"] == "no route"
    assert document["paper_table6"]["large"]["hierarchical"] == [52.10, 573.40, 0.24]
    assert len(document["scaling"]) == 3 and "targets" not in document
    json.loads(written["json"].read_text())  # strict JSON: no NaN
    assert written["markdown"].read_text().startswith("# Planning study")


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


def test_the_condensed_table_5_puts_both_volumes_beside_the_paper() -> None:
    ground, full = study(vp_s=0.03).table5, study(vp_s=0.3).table5
    lines = both_volumes_beside_paper(ground, full)
    assert lines[0] == "| Measure (median unless stated) | S3 ours | S3 paper |"
    cells = [[c.strip() for c in line.strip("|").split("|")] for line in lines[2:]]
    rows = {row[0]: row[1:] for row in cells}
    assert rows["VP at 0.5 m, ground band (ms)"][:2] == ["45.00", "1700.00"]  # 30 and 60 ms
    assert rows["VP at 0.5 m, full volume (ms)"][0] == "450.00"
    assert rows["VP/HP time at 0.5 m, searches, full (median / min)"][0] == "75,000 / 50,000"
    assert rows["valid segments: graph edges, HP, refined, VP 0.5 m"][0].startswith("97.6% of 41")
    assert "full volume" not in "\n".join(both_volumes_beside_paper(ground, []))


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
