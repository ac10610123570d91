"""Mission configuration: typed, validated, with defaults per world.

A :class:`MissionConfig` says everything a run depends on; the run directory keeps its resolved
form (every default filled in), so a run can be repeated from its ``config.json``.
"""

from __future__ import annotations

import functools
import math
import typing
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from seminspect.core.params import PRESETS, InspectionParams, PresetName
from seminspect.core.validation import build
from seminspect.core.vocabulary import BUILDING_FEATURES, VEHICLE_PARTS
from seminspect.graphs.lsg.naming import check_label
from seminspect.missions.xflie.features import world_feature_labels
from seminspect.worlds import World, open_world

Mode = Literal["ground", "aerial"]
NoiseName = Literal["ideal", "realistic"]
#: hierarchical: xFLIE; volumetric: 000 Sec VII-D's baseline between targets; frontier: pure
#: exploration that never inspects (Table 6's exploration baseline, GBPlanner2.0's role).
PlannerName = Literal["hierarchical", "volumetric", "frontier"]
#: A robot's job in a team: the explorer fills the Target layer, the inspector the layers below.
Role = Literal["explorer", "inspector"]
#: The teams a mission can field (beyond 000, after its Sec IX): one robot of each role.
TEAM_ROLES = frozenset({"explorer", "inspector"})

VEHICLE_CLASSES = ("car", "truck")


class _Strict(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")

    @model_validator(mode="before")
    @classmethod
    def _no_bools_for_numbers(cls, data: Any) -> Any:
        """YAML's true would pass as 1 for a number (a bool is an int to Python): refuse it."""
        if isinstance(data, dict):
            for key, value in data.items():
                if is_bool_for_number(cls, key, value):
                    raise ValueError(f"{key} takes a number, not true/false")
        return data


def is_bool_for_number(model: type[BaseModel], key: str, value: object) -> bool:
    """Whether ``value`` is a true/false given for ``model``'s field ``key`` that is no switch."""
    field = model.model_fields.get(key)
    if field is None or not isinstance(value, bool):
        return False
    annotation = field.annotation
    return not (annotation is bool or bool in typing.get_args(annotation))


class RobotConfig(_Strict):
    """The platform (a legged robot by default, as in 000 Sec VI-A)."""

    radius: float = Field(0.4, gt=0, le=3, description="body radius for collisions [m]")
    speed: float = Field(1.0, gt=0, le=10, description="speed limit [m/s]")
    yaw_rate: float = Field(0.8, gt=0, le=5, description="turn-rate limit [rad/s]")
    body_height: float = Field(
        0.7, gt=0, le=5, description="camera height (ground) or take-off height (aerial) [m]"
    )
    flight_height: float = Field(2.0, gt=0, le=50, description="height of Level-0 (aerial) [m]")
    camera_pitch_deg: float | None = Field(
        None,
        ge=0,
        le=60,
        description="camera tilt below the horizon [deg]; None: 0 (ground), 20 (aerial, to see "
        "what lies below the flight level)",
    )

    def planning_band(self) -> tuple[float, float]:
        """Height band a ground robot's planners keep clear [m]: above small bumps, up to half
        a metre over the camera."""
        return (0.3, max(1.0, self.body_height + 0.5))


class InspectionConfig(_Strict):
    """FLIE's local view planner (002 eqs 1-2) and level completion (000 eq 8)."""

    d_view: float = Field(2.5, gt=0.3, le=20, description="viewing distance [m]")
    overlap_h: float = Field(0.6, ge=0, lt=1, description="horizontal image overlap γ_H")
    overlap_v: float = Field(0.6, ge=0, lt=1, description="vertical image overlap γ_V")
    max_poses_per_level: int = Field(60, ge=3, description="safety cap on poses in one level")
    max_levels: int = Field(6, ge=1, description="cap on levels per target (aerial)")
    save_images: bool = Field(True, description="write view images to the run directory")


class ExplorationConfig(_Strict):
    """The exploration behaviours: 360-degree surveys and frontier hops."""

    survey_overlap: float = Field(
        0.1, ge=0, lt=0.9, description="overlap of consecutive survey images"
    )
    frontier_min_cells: int = Field(12, ge=1, description="smallest frontier worth visiting")
    frontier_max_hops: int = Field(40, ge=0, description="cap on frontier hops per mission")
    lidar_every_m: float = Field(2.0, gt=0, description="LiDAR scan spacing while driving [m]")
    camera_every_m: float = Field(4.0, gt=0, description="camera frame spacing while driving [m]")


class MissionConfig(_Strict):
    """One xFLIE mission. ``None`` fields take the world's default (see :func:`resolve`)."""

    world: str = "city"
    scenario: str | None = None
    seed: int = Field(0, ge=0)
    preset: PresetName | None = None
    mode: Mode | None = None
    noise: NoiseName = "realistic"
    planner: PlannerName = "hierarchical"
    charge_planning_time: bool = Field(
        False,
        description="the robot waits for every planner call's wall time, so slow planning costs "
        "mission time (000 Sec VII-D); off by default because wall time varies between runs",
    )
    time_budget_s: float | None = Field(
        None, gt=0, allow_inf_nan=False, description="simulated seconds"
    )
    map_resolution: float = Field(0.3, ge=0.1, le=1.0, description="robot's occupancy map [m]")
    map_carving_spacing: float | None = Field(
        None,
        gt=0,
        le=4,
        description="thin the rays that carve free space near the sensor to this many cells "
        "apart (mapping.carving: faster, a few free cells stay unknown); None: every ray, exact",
    )
    target_classes: tuple[str, ...] | None = None
    feature_labels: tuple[str, ...] | None = Field(
        None,
        description="part names recorded as features; None: every part the world's targets "
        "carry but body, roof and wall (missions.xflie.features)",
    )
    localisation: Literal["median", "cluster"] = "cluster"
    min_score: float = Field(
        0.6, ge=0, le=1, description="segmentation confidence below which detections are ignored"
    )
    mask_erosion_px: int = Field(
        2, ge=0, le=20, description="erosion of object masks before localisation (000 Sec VIII)"
    )
    gamma_thresh: float | None = Field(
        None, ge=0, description="Γ_thresh of eq (8); None: the ORB matcher's calibration"
    )
    odometry_drift_per_m: float | None = Field(
        None, ge=0, le=1, description="localisation drift [m per sqrt(m)]; None: see mission_noise"
    )
    robot: RobotConfig = RobotConfig()
    inspection: InspectionConfig | None = None
    exploration: ExplorationConfig = ExplorationConfig()
    robots: tuple[Role, ...] | None = Field(
        None,
        description="a team sharing one 3DLSG, e.g. ('explorer', 'inspector'); None: one robot "
        "that explores and inspects (000)",
    )

    @field_validator("feature_labels")
    @classmethod
    def _labels_name_nodes(cls, labels: tuple[str, ...] | None) -> tuple[str, ...] | None:
        """A feature label names graph nodes: refuse one the graph would refuse mid-mission."""
        for label in labels or ():
            check_label(label)
        return labels

    @field_validator("robots")
    @classmethod
    def _one_of_each_role(cls, robots: tuple[Role, ...] | None) -> tuple[Role, ...] | None:
        if robots is not None and (len(robots) != len(TEAM_ROLES) or set(robots) != TEAM_ROLES):
            raise ValueError(
                f"a team is one explorer and one inspector, got {','.join(robots) or 'none'}"
            )
        return robots

    @model_validator(mode="after")
    def _team_inspects(self) -> MissionConfig:
        if self.robots is not None and self.planner == "frontier":
            raise ValueError("a team inspects: the frontier planner only explores")
        return self


class ResolvedMissionConfig(MissionConfig):
    """A :class:`MissionConfig` with every world default filled in (made by :func:`resolve`).

    The same fields, serialised the same way; only the types promise that nothing is ``None``
    any more, so code that runs a mission never checks.
    """

    preset: PresetName
    mode: Mode
    time_budget_s: float = Field(gt=0, description="simulated seconds")
    target_classes: tuple[str, ...]
    feature_labels: tuple[str, ...]
    inspection: InspectionConfig

    @property
    def params(self) -> InspectionParams:
        """The Table 1/2 parameters of the preset."""
        return PRESETS[self.preset]


#: 000 Sec VII-D: time limits of 700, 1400 and 2800 s for the 5, 10 and 20-vehicle scenarios,
#: the paper's average completion times on its layout. Our city scatters its vehicles over the
#: whole site, and complete missions take longer (city small: 1,030-1,180 s over seeds 0-2), so
#: missions default to a one-hour safety budget and end when done; the comparison study of
#: 000 Table 6 sets these budgets explicitly.
CITY_BUDGETS = {"small": 700.0, "medium": 1400.0, "large": 2800.0}
DEFAULT_BUDGET_S = 3600.0

#: Level cap among collapsed buildings. 000 gives no cap: levels climb until the structure's
#: top is in view (eq 8 closes each one), at the 1.66 m vertical step 4 levels on the 7 m fire
#: station and 10 on the 17.5 m industrial building. The cap is set above what the sites'
#: airspace holds (12 levels from 2 m under the industrial site's 22 m, the robot's clearance
#: kept), so the top, not the cap, ends the climb.
COLLAPSED_MAX_LEVELS = 16
#: Per-world defaults: preset, mode, target classes, features, viewing distance, level cap,
#: budget.
WORLD_DEFAULTS: dict[str, dict[str, Any]] = {
    "city": {
        "preset": "urban-simulated", "mode": "ground", "d_view": 2.5, "budget": DEFAULT_BUDGET_S,
        "scenario": "medium",
    },
    "campus": {"preset": "urban-experimental", "mode": "ground", "d_view": 2.5, "budget": 900.0},
    "subterranean": {
        "preset": "urban-experimental", "mode": "ground", "d_view": 1.3, "budget": 400.0,
    },
    "collapsed-buildings": {
        "preset": "collapsed-buildings", "mode": "aerial", "d_view": 4.0, "budget": 2400.0,
        "max_levels": COLLAPSED_MAX_LEVELS, "classes": ("building",), "features": BUILDING_FEATURES,
    },
}  # fmt: skip
#: A user world (``world`` is a path) takes the city's defaults; it has no scenarios.
USER_WORLD_DEFAULTS = {k: v for k, v in WORLD_DEFAULTS["city"].items() if k != "scenario"}


def make_config(values: dict[str, Any]) -> MissionConfig:
    """Validate raw values (e.g. from the CLI or a JSON file) with one readable error line."""
    return build(MissionConfig, values, "mission setting")


def resolve(config: MissionConfig, world: World | None = None) -> ResolvedMissionConfig:
    """Fill every ``None`` field with the world's default.

    Unset (or empty) ``feature_labels`` become the parts the world's targets carry
    (:func:`~seminspect.missions.xflie.features.world_feature_labels`): a user world is read
    for them unless it is given as ``world``; a built-in world's are its vocabulary
    (``VEHICLE_PARTS``, ``BUILDING_FEATURES``), which is what its targets carry.
    """
    defaults = WORLD_DEFAULTS.get(config.world, USER_WORLD_DEFAULTS)
    classes = config.target_classes or defaults.get("classes", VEHICLE_CLASSES)
    budget = defaults["budget"]
    levels = {"max_levels": defaults["max_levels"]} if "max_levels" in defaults else {}
    inspection = config.inspection or InspectionConfig(d_view=defaults["d_view"], **levels)
    return ResolvedMissionConfig.model_validate(
        dict(config)
        | {
            "scenario": default_scenario(config),
            "preset": config.preset or defaults["preset"],
            "mode": config.mode or defaults["mode"],
            "time_budget_s": config.time_budget_s or budget,
            "target_classes": classes,
            "feature_labels": config.feature_labels or _features(config, classes, world),
            "inspection": inspection,
        }
    )


def default_scenario(config: MissionConfig) -> str | None:
    """The scenario a mission runs: the configured one or the world's default."""
    return config.scenario or WORLD_DEFAULTS.get(config.world, USER_WORLD_DEFAULTS).get("scenario")


def _features(
    config: MissionConfig, classes: tuple[str, ...], world: World | None
) -> tuple[str, ...]:
    """The feature labels a mission takes when its configuration names none."""
    if config.world in WORLD_DEFAULTS:
        return WORLD_DEFAULTS[config.world].get("features", VEHICLE_PARTS)
    if world is not None:
        return world_feature_labels(world, classes)
    return _user_world_features(config.world, classes)


@functools.lru_cache(maxsize=8)
def _user_world_features(path: str, classes: tuple[str, ...]) -> tuple[str, ...]:
    """A user world's feature labels, read once per process: a sweep resolves every task's
    configuration, and the mesh need not be loaded for each just to list its parts."""
    return world_feature_labels(open_world(path), classes)


def inspects(planner: str) -> bool:
    """Whether missions with this planner inspect targets (the frontier explorer does not)."""
    return planner != "frontier"


def survey_headings(fov_deg: float, overlap: float) -> int:
    """How many views a 360-degree survey takes with this field of view and overlap."""
    return max(3, math.ceil(360.0 / (fov_deg * (1.0 - overlap))))
