"""The planning study's Table 5 records: ratios, the ground band, a run compared query by
query, and the study refusing an unknown volume."""

import math
from pathlib import Path

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.mapping.voxel import VoxelMap
from seminspect.studies.xflie import study as planning_study
from seminspect.studies.xflie.comparison import HierarchicalTiming, VolumetricResult
from seminspect.studies.xflie.study import PathCheck, QueryComparison, above_ground, compare_run


def _comparison(hp_s: float, vp_s: float, hp_m: float, vp_m: float) -> QueryComparison:
    timing = HierarchicalTiming(hp_s / 4, hp_s / 4, hp_s / 2, hp_s, 2 * hp_s, 5)
    answer = VolumetricResult(0.5, vp_s, vp_m, 10, 0.0, np.zeros((2, 3)))
    check = PathCheck(3, 4)
    return QueryComparison(
        "Visit x-1 in Level-0 of car-1", "car-1/Level-0/x-1", 10.0, timing, 5.0, hp_m, check,
        0.8 * hp_m, hp_s, check, (answer,), (check,),
    )  # fmt: skip


def test_ratios_divide_volumetric_by_hierarchical() -> None:
    q = _comparison(hp_s=1e-5, vp_s=1e-2, hp_m=12.0, vp_m=10.0)
    assert q.time_ratio(0.5) == pytest.approx(2000)  # against the searches (half of plan)
    assert q.time_ratio(0.5, "plan") == pytest.approx(1000)
    assert q.time_ratio(0.5, "query") == pytest.approx(500)
    assert q.time_ratio(0.5, "refined") == pytest.approx(1e-2 / 3e-5)
    assert q.length_ratio(0.5) == pytest.approx(1.2)
    assert q.length_ratio(0.5, refined=True) == pytest.approx(0.96)
    assert not q.hp_check.all_valid and PathCheck(2, 2).all_valid
    with pytest.raises(InvalidInputError, match=r"0\.7"):
        q.volumetric(0.7)


def test_the_ground_band_starts_above_the_maps_ground_cells() -> None:
    coarse = VoxelMap.empty([0, 0, -0.35], [10, 10, 5], 0.7)  # ground in the bottom layer
    assert above_ground((0.3, 1.2), coarse) == pytest.approx((0.35, 1.2), abs=1e-5)
    fine = VoxelMap.empty([0, 0, -0.2], [10, 10, 5], 0.4)
    assert above_ground((0.3, 1.2), fine) == (0.3, 1.2)


@pytest.mark.slow
def test_a_run_is_compared_query_by_query(small_mission_dir: Path) -> None:
    result = compare_run(small_mission_dir, count=3, repeats=3, vp_repeats=1, resolutions=(0.5,))
    assert len(result.queries) == 3 and result.inspected_targets >= 3
    assert result.edge_check.all_valid and result.edge_check.segments > 40
    np.testing.assert_allclose(result.start, planning_study.final_pose(small_mission_dir))
    for q in result.queries:
        assert q.hp_check.all_valid and q.refined_check.all_valid
        assert q.refined_length_m <= q.hp_length_m + 1e-9
        vp = q.volumetric(0.5)
        assert vp.error is None and vp.length >= q.straight_m - 1.0
        assert math.isfinite(q.time_ratio(0.5, "query")) and q.hp.repeats == 3


@pytest.mark.slow
def test_the_full_volume_baseline_searches_every_height(small_mission_dir: Path) -> None:
    args = {"count": 2, "repeats": 1, "vp_repeats": 1, "resolutions": (0.5,)}
    ground = compare_run(small_mission_dir, **args)
    full = compare_run(small_mission_dir, volume="full", **args)
    assert ground.volume == "ground" and full.volume == "full"
    for flat, free in zip(ground.queries, full.queries, strict=True):
        assert flat.query == free.query and flat.hp_length_m == free.hp_length_m
        answer, check = free.volumetric(0.5), free.vp_checks[0]
        assert answer.error is None and check.segments == len(answer.waypoints) - 1
        # A 0.5 m grid keeps its clearance from cell centres: now and then a cell's worth short.
        assert check.valid >= 0.9 * check.segments
        # It flies no lower than the robot's centre, and up to where the map ends.
        assert answer.waypoints[:, 2].min() >= full.start[2] - 1e-6
    assert sum(q.vp_checks[0].segments for q in full.queries) > 10


@pytest.mark.slow
def test_an_unknown_volume_is_refused(small_mission_dir: Path) -> None:
    with pytest.raises(InvalidInputError, match="unknown volume 'sky'"):
        compare_run(small_mission_dir, volume="sky")
    with pytest.raises(InvalidInputError, match="unknown volume 'sky'"):
        planning_study.run_study(["small"], small_mission_dir.parent, volume="sky")
