"""The golden mission: city small, seed 0, realistic noise, pinned figure for figure.

Every figure of the run that does not depend on the machine (000 Table 3's row, the target
matches and their errors, the simulated time and the mission's counts) must equal
``data/golden/city-small-seed0.json`` exactly; wall-clock figures (wall time, CPU and planning
load, planning times) are left out. The same row is published in docs/reproduction.md, and a
second test holds the two together.

A change of behaviour that moves these figures must update the golden file and the docs in the
same commit: rerun with ``SEMINSPECT_UPDATE_GOLDEN=1`` to rewrite the file from the new run,
then ``bench/reproduction.py`` to regenerate the published tables.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path
from typing import Any

import pytest

from seminspect.core.io import atomic_write_text
from seminspect.missions.config import make_config
from seminspect.missions.run import run_mission

GOLDEN = Path(__file__).parent / "data" / "golden" / "city-small-seed0.json"
DOCS = Path(__file__).resolve().parents[2] / "docs" / "reproduction.md"
#: The golden configuration: the published city small row, seed 0, every other setting default.
CONFIG = {"world": "city", "scenario": "small", "seed": 0}
#: Mission figures that come from simulated time and seeded randomness only.
MISSION_FIGURES = ("sim_time_s", "distance_m", "frames", "lidar_scans", "collisions")
TABLE6_FIGURES = (
    "localisation_rmse_m",
    "localisation_rmse_3d_m",
    "surface_coverage_pct",
    "bbox_volume_m3",
)


def reproducible_figures(metrics: dict[str, Any]) -> dict[str, Any]:
    """The figures of a run's metrics that must not change unless the behaviour does."""
    return {
        "config": CONFIG,
        "state": metrics["state"],
        "stop_reason": metrics["stop_reason"],
        "table3": {k: v for k, v in metrics["table3"].items() if k != "avg_planning_time_ms"},
        "table6": {k: metrics["table6"][k] for k in TABLE6_FIGURES},
        "targets": metrics["targets"],
        "mission": {
            **{k: metrics["mission"][k] for k in MISSION_FIGURES},
            "level_endings": metrics["mission"]["level_endings"],
            "local_plans": metrics["mission"]["local_plans"],
        },
    }


@pytest.fixture(scope="module")
def golden_run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    out = tmp_path_factory.mktemp("golden") / "city-small-seed0"
    metrics = run_mission(make_config(CONFIG), out).metrics
    assert metrics is not None
    return reproducible_figures(metrics.to_json())


@pytest.mark.slow
def test_the_golden_mission_reproduces_its_figures_exactly(golden_run) -> None:
    # A JSON round trip gives the float values the file can hold (repr is exact).
    measured = json.loads(json.dumps(golden_run))
    if os.environ.get("SEMINSPECT_UPDATE_GOLDEN"):
        atomic_write_text(GOLDEN, json.dumps(measured, indent=1) + "\n")
    expected = json.loads(GOLDEN.read_text(encoding="utf-8"))
    assert measured["table3"] == expected["table3"]
    assert measured["targets"]["matches"] == expected["targets"]["matches"]
    assert measured == expected


def published_row(text: str) -> list[str]:
    """The cells of the city small, seed 0 row of docs/reproduction.md's Table 3."""
    match = re.search(r"^\| city small \| 0 \|(.*)\|$", text, re.MULTILINE)
    assert match, "docs/reproduction.md has no city small, seed 0 row"
    return [cell.strip() for cell in match.group(1).split("|")]


def test_the_docs_publish_the_golden_row() -> None:
    golden = json.loads(GOLDEN.read_text(encoding="utf-8"))
    t3, t6, mission = golden["table3"], golden["table6"], golden["mission"]
    layers = " ".join("/".join(map(str, t3[k])) for k in ("target", "level", "pose", "feature"))
    endings = mission["level_endings"]
    expected = [
        layers,
        "/".join(map(str, t3["unified"])),
        f"{t3['reconciled_pct']:.1f}",
        f"{t3['detected_pct']:.0f}/{t3['inspected_pct']:.0f}",
        str(golden["targets"]["false_targets"]),
        f"{t6['localisation_rmse_m']:.3f}",
        f"{t6['surface_coverage_pct']:.1f}",
        f"{t6['bbox_volume_m3']:.0f}",
        str(mission["collisions"]),
        f"{endings['similarity']}/{endings['cap']}",
        f"{mission['sim_time_s']:.0f}",
    ]
    # the last column, the real-time factor, is wall-clock and not pinned
    assert published_row(DOCS.read_text(encoding="utf-8"))[:-1] == expected
