"""A made-up planning study with known figures, for the report and CLI tests."""

import math
from pathlib import Path

import numpy as np

from seminspect.studies.xflie.comparison import HierarchicalTiming, VolumetricResult
from seminspect.studies.xflie.missions import MissionOutcome
from seminspect.studies.xflie.scaling import ScalingPoint
from seminspect.studies.xflie.study import (
    RESOLUTIONS,
    PathCheck,
    PlanningStudy,
    QueryComparison,
    RunComparison,
)


def query(vp_s: float, hp_m: float = 110.0, refined_m: float = 100.0) -> QueryComparison:
    timing = HierarchicalTiming(2e-6, 4e-6, 6e-6, 2e-5, 3e-5, 200)
    answers = tuple(
        VolumetricResult(r, vp_s, 100.0, 1000, 0.0, np.zeros((3, 3)))
        if r != 0.7
        else VolumetricResult(r, math.nan, math.nan, 0, 0.0, np.empty((0, 3)), "no route")
        for r in RESOLUTIONS
    )
    checks = tuple(PathCheck(2, 2) for _ in answers)
    return QueryComparison(
        "Visit front-bumper-1 in Level-0 of car-2", "car-2/Level-0/front-bumper-1", 90.0,
        timing, 60.0, hp_m, PathCheck(12, 12), refined_m, 7e-5, PathCheck(4, 4), answers, checks,
    )  # fmt: skip


def study(vp_s: float = 0.03) -> PlanningStudy:
    run = RunComparison(
        "large", Path("runs/large"), np.array([1.0, 2.0, 0.7]), 1000, 20,
        {r: 0.01 for r in RESOLUTIONS}, PathCheck(40, 41), 200, 3,
        [query(vp_s), query(2 * vp_s, refined_m=120.0)],
    )  # fmt: skip
    points = [
        ScalingPoint(n, 50 * n, 100 * n, 1e4 * n, 1e4 * n, 3, 5e-6 * n**0.3, 6e-6 * n**0.3,
                     2e-5 * n**0.3, 3e-5 * n**0.3, 20, 1e-4 * n, 2e-4 * n, 500, 0,
                     20 * n**0.7, 5 * n**0.7)
        for n in (20, 200, 2000)
    ]  # fmt: skip
    outcome = MissionOutcome(
        "large", "volumetric", Path("runs/v"), 101.0, 0.5, 480.0, 500.0, 45.0, 0.05, 18, 20,
        2800.0, 240.0, 60,
    )  # fmt: skip
    return PlanningStudy([run], points, [outcome])
