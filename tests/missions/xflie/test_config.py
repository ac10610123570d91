import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.missions.xflie.config import (
    CITY_BUDGETS,
    DEFAULT_BUDGET_S,
    MissionConfig,
    make_config,
    resolve,
    survey_headings,
)
from seminspect.planning.view_planner import ViewConstraints
from seminspect.worlds import generate_world


def test_worlds_bring_their_papers_presets() -> None:
    city = resolve(MissionConfig())
    assert (city.world, city.scenario, city.preset, city.mode) == (
        "city",
        "medium",
        "urban-simulated",
        "ground",
    )
    assert city.time_budget_s == DEFAULT_BUDGET_S  # a safety limit: missions end when done
    assert CITY_BUDGETS == {"small": 700.0, "medium": 1400.0, "large": 2800.0}  # 000 Sec VII-D
    assert city.target_classes == ("car", "truck")
    collapsed = resolve(MissionConfig(world="collapsed-buildings", scenario="industrial"))
    assert (collapsed.preset, collapsed.mode, collapsed.target_classes) == (
        "collapsed-buildings",
        "aerial",
        ("building",),
    )
    assert collapsed.params.d_check_T == 8.0  # 000 Table 2


def test_collapsed_building_levels_end_at_the_top_not_at_the_cap() -> None:
    config = resolve(MissionConfig(world="collapsed-buildings", scenario="industrial"))
    step = ViewConstraints(d_view=config.inspection.d_view).vertical_step
    airspace = generate_world("collapsed-buildings", "industrial").bounds[1][2]
    # more levels than the site's airspace holds at the vertical step, so the top ends them
    assert config.inspection.max_levels * step > airspace
    assert resolve(MissionConfig()).inspection.max_levels < config.inspection.max_levels


def test_explicit_settings_win_over_defaults() -> None:
    config = resolve(make_config({"world": "city", "mode": "aerial", "time_budget_s": 90}))
    assert (config.mode, config.time_budget_s) == ("aerial", 90)


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ({"seed": -1}, "seed"),
        ({"preset": "urban"}, "preset"),
        ({"mode": "swimming"}, "mode"),
        ({"time_budget_s": 0}, "time_budget_s"),
        ({"robot": {"radius": -1}}, "robot.radius"),
        ({"map_carving_spacing": 0}, "map_carving_spacing"),
        ({"warp_drive": True}, "warp_drive"),
        ({"robots": ["explorer", "pilot"]}, "robots.1: Input should be 'explorer' or"),
        ({"robots": ["inspector", "inspector"]}, "one explorer and one inspector"),
        ({"robots": ["explorer"]}, "one explorer and one inspector, got explorer"),
        # YAML's true is an int to Python: it would run seed 1, a 1 s budget, a cap of 1 level
        ({"seed": True}, "seed takes a number, not true/false"),
        ({"time_budget_s": True}, "time_budget_s takes a number, not true/false"),
        ({"inspection": {"max_levels": True}}, "inspection: max_levels takes a number"),
    ],
)
def test_impossible_settings_give_one_line(values, message) -> None:
    with pytest.raises(InvalidInputError, match=message):
        make_config(values)


def test_a_team_is_one_explorer_and_one_inspector_in_either_order() -> None:
    for robots in (["explorer", "inspector"], ["inspector", "explorer"]):
        assert make_config({"robots": robots}).robots == tuple(robots)
    assert make_config({}).robots is None


def test_survey_covers_the_full_circle() -> None:
    assert survey_headings(69.4, 0.1) == 6  # 6 x 62.5 deg >= 360 deg
    assert survey_headings(86.0, 0.1) == 5


def test_a_resolved_config_serialises_as_the_config_it_came_from() -> None:
    raw = make_config({"world": "subterranean"})
    resolved = resolve(raw)
    assert list(resolved.model_dump()) == list(raw.model_dump())  # config.json keeps its keys
    assert resolved.inspection.d_view == 1.3 and resolved.scenario is None
    assert resolve(resolved) == resolved
