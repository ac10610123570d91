"""bench/planning_targets.py judges a written planning study against issue 5's targets."""

from pathlib import Path

import pytest

from bench_scripts import bench_script
from seminspect.core.io import read_versioned_json
from seminspect.studies.xflie.tables import STUDY_FORMAT, write_study
from study_fakes import study


def _script():
    return bench_script("planning_targets")


def _document(tmp_path: Path, vp_s: float) -> dict:
    written = write_study(study(vp_s=vp_s), tmp_path / f"vp-{vp_s}")
    return read_versioned_json(written["json"], STUDY_FORMAT, [1])


def test_targets_are_judged_on_the_measured_figures(tmp_path: Path) -> None:
    targets = _script()
    met = targets.targets_met(_document(tmp_path, 0.03))
    ratio = met["time_ratio_large"]
    assert ratio["min_search"] == pytest.approx(0.03 / 6e-6)
    assert ratio["met_search"] and ratio["min_end_to_end"] == pytest.approx(1000)
    refined = met["refined"]
    assert refined["mean_length_ratio"] == pytest.approx(1.1) and refined["met_length"]
    assert refined["min_time_ratio"] == pytest.approx(0.03 / 1e-4) and refined["met_time"]
    assert met["growth"]["exponent_search"] == pytest.approx(0.3) and met["growth"]["met"]
    every_met = targets.targets_met(_document(tmp_path, 0.06))
    assert "not met" not in targets.targets_markdown(every_met)
    slow_baseline = targets.targets_met(_document(tmp_path, 0.003))
    assert not slow_baseline["time_ratio_large"]["met_end_to_end"]
    assert "not met" in targets.targets_markdown(slow_baseline)
