"""A world without targets: the mission warns as it starts that it will only explore."""

import warnings

import pytest

from seminspect.missions.xflie.build import build_mission
from seminspect.missions.xflie.config import make_config, resolve
from seminspect.worlds import save_world
from seminspect.worlds.checks import WorldWarning
from sim_worlds import box_world


def test_a_mission_on_a_world_without_targets_warns_as_it_starts(tmp_path) -> None:
    save_world(box_world(), tmp_path / "crate-only")  # one crate, no car or truck
    config = resolve(make_config({"world": str(tmp_path / "crate-only")}))
    with pytest.warns(WorldWarning, match="has no targets .*the mission will only explore"):
        build_mission(config, None)


def test_a_mission_with_targets_starts_without_a_word() -> None:
    config = resolve(make_config({"world": "campus", "scenario": "small"}))
    with warnings.catch_warnings():
        warnings.simplefilter("error", WorldWarning)
        build_mission(config, None)
