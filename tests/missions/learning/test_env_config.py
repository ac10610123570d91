"""The environment's settings are validated; the episode length follows from them."""

import pytest
from pydantic import ValidationError

from seminspect.missions.learning.env_config import EnvConfig


def test_the_default_episode_is_004s_90_seconds_at_10_hz():
    assert EnvConfig().steps_per_episode == 900


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"map_cells": 20}, "odd"),
        ({"image_size": (0, 54)}, "positive"),
        ({"robot_radius": 0.5, "d_coll": 0.3}, "must not exceed d_coll"),
        ({"face_reward": "repaid", "shaping_discount": 0.99}, "fraction reward only"),
        ({"shaping_discount": 1.0}, "less than 1"),
    ],
)
def test_inconsistent_settings_are_refused(changes, message):
    with pytest.raises(ValidationError, match=message):
        EnvConfig(**changes)
