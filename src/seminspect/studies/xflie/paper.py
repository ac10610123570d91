"""000's own numbers for the planning study: the rows of Table 5 and the cells of Table 6, which
the study's tables print beside ours."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class PaperQuery:
    """One row of 000 Table 5 (seconds and metres)."""

    query: str
    target_layer_s: float
    target_layer_m: float
    pose_layer_s: float
    pose_layer_m: float
    vp05_s: float
    vp05_m: float
    vp07_s: float
    vp07_m: float


#: 000 Table 5, by scenario (1: small, 2: medium, 3: large).
PAPER_TABLE5: dict[str, tuple[PaperQuery, ...]] = {
    "small": (
        PaperQuery("Visit front-bumper-1 in Level-0 of truck-4",
                   1.7e-5, 32.33, 1.1e-4, 49.92, 0.526, 45.420, 0.220, 48.600),
        PaperQuery("Visit back-left-door-1 in Level-0 of car-0",
                   2.2e-5, 48.44, 1.1e-4, 56.86, 0.632, 45.229, 0.250, 46.536),
        PaperQuery("Visit front-bumper-1 in Level-0 of car-1",
                   1.6e-5, 16.11, 5.8e-5, 19.74, 0.560, 16.020, 0.110, 17.180),
    ),
    "medium": (
        PaperQuery("Visit trunk-1 in Level-0 of truck-9",
                   4.0e-5, 49.80, 2.1e-4, 70.83, 1.085, 57.479, 0.431, 59.580),
        PaperQuery("Visit front-glass-1 in Level-0 of truck-6",
                   3.5e-5, 89.44, 3.2e-4, 105.86, 1.150, 76.000, 0.369, 77.179),
        PaperQuery("Visit front-bumper-1 in Level-0 of truck-2",
                   2.7e-5, 68.60, 2.2e-4, 66.53, 1.030, 53.414, 0.390, 53.815),
    ),
    "large": (
        PaperQuery("Visit front-bumper-1 in Level-0 of car-9",
                   7.74e-5, 85.16, 3.4e-4, 95.85, 1.7, 77.63, 0.75, 80.76),
        PaperQuery("Visit front-glass-1 in Level-1 of truck-16",
                   7.71e-5, 136.48, 5.4e-4, 145.50, 1.9, 102.15, 0.53, 103.40),
        PaperQuery("Visit front-right-door-1 in Level-0 of truck-18",
                   7.6e-5, 110.69, 4.1e-4, 119.52, 0.35, 73.08, 0.45, 74.19),
    ),
}  # fmt: skip

#: 000 Table 6: (computational load %, inspection coverage m^3, target localisation RMSE m);
#: the frontier explorer stands beside the paper's GBPlanner2.0 row.
PAPER_TABLE6: dict[str, dict[str, tuple[float, float, float]]] = {
    "small": {
        "volumetric": (103.57, 103.02, 0.19),
        "frontier": (87.63, 64.19, 0.66),
        "hierarchical": (42.68, 107.74, 0.17),
    },
    "medium": {
        "volumetric": (113.755, 298.94, 0.28),
        "frontier": (93.81, 215.22, 0.58),
        "hierarchical": (44.66, 331.40, 0.195),
    },
    "large": {
        "volumetric": (118.42, 506.84, 0.40),
        "frontier": (101.40, 372.48, 1.37),
        "hierarchical": (52.10, 573.40, 0.24),
    },
}
