"""The golden mission: city small, seed 0, realistic noise, pinned figure for figure.

Every figure of the run that does not depend on the machine (000 Table 3's row, the target
matches and their errors, the simulated time and the mission's counts) must equal
``data/golden/city-small-seed0.json`` exactly; wall-clock figures (wall time, CPU and planning
load, planning times) are left out. The same row is published in docs/reproduction.md, and a
second test holds the two together.

Floating-point results depend on the CPU (``core.provenance.numeric_platform``: Embree's SIMD
path, the vendor's reciprocal estimates, OpenBLAS's kernels), and a mission's path drifts apart
from the first differing bit. So each golden file records the platform it was made on, and the
run is held to the file of a matching platform: ``city-small-seed0.json`` (the published row,
made on the AMD EPYC development machine) or one recorded since on another kind of machine. On
a platform with no golden file the exact comparison is skipped, saying so; every other mission
test still runs there.

A change of behaviour that moves these figures must update the golden files and the docs in
the same commit: rerun with ``SEMINSPECT_UPDATE_GOLDEN=1`` to rewrite this platform's file from
the new run, then ``bench/reproduction.py`` to regenerate the published tables.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path
from typing import Any

import pytest

from seminspect.core.io import atomic_write_text
from seminspect.core.provenance import numeric_platform, platform_label
from seminspect.missions.config import make_config
from seminspect.missions.run import run_mission

GOLDEN_DIR = Path(__file__).parent / "data" / "golden"
#: The figures of the published row, made on the development machine.
GOLDEN = GOLDEN_DIR / "city-small-seed0.json"
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


def golden_files() -> dict[Path, dict[str, Any]]:
    """Every golden file of the golden configuration, by path."""
    paths = sorted(GOLDEN_DIR.glob("city-small-seed0*.json"))
    return {path: json.loads(path.read_text(encoding="utf-8")) for path in paths}


def golden_for(platform: dict[str, str]) -> Path | None:
    """The golden file made on a machine with ``platform``'s floating-point paths: one whose
    recorded fields all match (the most specific, where several do)."""
    matching = [
        (len(document["platform"]), path)
        for path, document in golden_files().items()
        if all(platform.get(key) == value for key, value in document["platform"].items())
    ]
    return max(matching)[1] if matching else None


def test_every_golden_file_names_its_platform_and_the_golden_configuration() -> None:
    documents = golden_files()
    assert GOLDEN in documents
    for path, document in documents.items():
        assert document["config"] == CONFIG, path.name
        assert document["platform"].get("machine"), path.name


def test_a_machine_takes_the_golden_file_of_its_platform() -> None:
    amd = {"machine": "x86_64", "cpu_vendor": "AuthenticAMD", "simd": "avx2", "blas_kernels": "Zen"}
    assert golden_for(amd) == GOLDEN
    assert golden_for({**amd, "cpu_vendor": "NoSuchVendor"}) is None


@pytest.mark.slow
def test_the_golden_mission_reproduces_its_figures_exactly(golden_run) -> None:
    # A JSON round trip gives the float values the file can hold (repr is exact).
    measured = json.loads(json.dumps(golden_run))
    platform = numeric_platform()
    path = golden_for(platform)
    if os.environ.get("SEMINSPECT_UPDATE_GOLDEN"):
        recorded = json.loads(path.read_text(encoding="utf-8"))["platform"] if path else platform
        path = path or GOLDEN_DIR / f"city-small-seed0-{platform_slug(platform)}.json"
        document = {"platform": recorded, **measured}
        atomic_write_text(path, json.dumps(document, indent=1) + "\n")
    if path is None:
        pytest.skip(
            f"no golden figures for this machine ({platform_label(platform)}): floating-point "
            "results differ between CPUs; record them with SEMINSPECT_UPDATE_GOLDEN=1 at a "
            "commit whose golden test passes on a recorded machine"
        )
    expected = json.loads(path.read_text(encoding="utf-8"))
    del expected["platform"]
    assert measured["table3"] == expected["table3"]
    assert measured["targets"]["matches"] == expected["targets"]["matches"]
    assert measured == expected


def platform_slug(platform: dict[str, str]) -> str:
    """A file-name form of a platform, e.g. ``x86_64-genuineintel-avx512f-skylakex``."""
    return "-".join(
        platform[key] for key in ("machine", "cpu_vendor", "simd", "blas_kernels")
    ).lower()


def platform_table() -> str:
    """The golden row of every recorded platform, as docs/reproduction.md lists them."""
    lines = [
        "| machine (`numeric_platform`) | layers T/L/P/F | unified | reconciled % | RMSE m "
        "| coverage % | sim s |",
        "|---|---|---|---|---|---|---|",
    ]
    for document in golden_files().values():
        t3, t6 = document["table3"], document["table6"]
        layers = " ".join("/".join(map(str, t3[k])) for k in ("target", "level", "pose", "feature"))
        cells = [
            platform_label(document["platform"]),
            layers,
            "/".join(map(str, t3["unified"])),
            f"{t3['reconciled_pct']:.1f}",
            f"{t6['localisation_rmse_m']:.3f}",
            f"{t6['surface_coverage_pct']:.1f}",
            f"{document['mission']['sim_time_s']:.0f}",
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def test_the_docs_list_the_golden_row_of_every_platform() -> None:
    text = DOCS.read_text(encoding="utf-8")
    block = re.compile(
        r"(<!-- BEGIN golden-platforms -->\n).*?(<!-- END golden-platforms -->)", re.S
    )
    if os.environ.get("SEMINSPECT_UPDATE_GOLDEN"):
        text = block.sub(lambda m: m.group(1) + platform_table() + "\n" + m.group(2), text)
        atomic_write_text(DOCS, text)
    match = block.search(text)
    assert match, "docs/reproduction.md has no golden-platforms block"
    assert platform_table() in match.group(0)


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
